#!/usr/bin/env python3
"""Writes a ROS 2 sqlite3 bag (.db3, rosbag2's schema) with Python's sqlite3 module from
make_ros2_fixtures.mjs's OUT_PREFIX.cdr.json (the topics, each message's CDR bytes and receive
time in ns): the messages table's timestamp is the receive time.

  python3 make_db3.py IN.cdr.json OUT.db3"""
import base64
import json
import os
import sqlite3
import sys

source, out = sys.argv[1], sys.argv[2]
with open(source) as f:
    bag = json.load(f)
if os.path.exists(out):
    os.remove(out)
db = sqlite3.connect(out)
db.executescript("""
CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);
CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL,
                      metadata TEXT NOT NULL);
CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,
                    serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL,
                    type_description_hash TEXT NOT NULL);
CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL,
                      timestamp INTEGER NOT NULL, data BLOB NOT NULL);
CREATE INDEX timestamp_idx ON messages (timestamp ASC);
""")
db.execute("INSERT INTO schema VALUES (4, 'jazzy')")
ids = {}
for i, t in enumerate(bag["topics"], start=1):
    ids[t["name"]] = i
    db.execute("INSERT INTO topics VALUES (?, ?, ?, 'cdr', '', '')", (i, t["name"], t["type"]))
db.executemany("INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)",
               ((ids[m["topic"]], int(m["timestamp"]), base64.b64decode(m["data"]))
                for m in bag["messages"]))
db.commit()
db.close()
