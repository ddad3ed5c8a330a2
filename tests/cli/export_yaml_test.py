#!/usr/bin/env python3
"""Issue 35 item 6: what plumb writes as YAML parses back, with a YAML parser, to exactly the
keys it wrote; a Kalibr topic that would add keys (a newline and "evil: true") is refused
before anything is written.

Usage: export_yaml_test.py PLUMB SOURCE_DIR WORK_DIR"""
import os
import subprocess
import sys

import yaml

plumb, source, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
session = os.path.join(source, "data/mikoff/imu0.log")
if not os.path.exists(session):
    print("skipped: bundled data absent: " + session)
    sys.exit(77)
base = [plumb, "calibrate", session, "--columns", "ax,ay,az,gx,gy,gz", "--rate", "100"]
expected = {"rostopic", "update_rate", "accelerometer_noise_density",
            "accelerometer_random_walk", "gyroscope_noise_density", "gyroscope_random_walk"}

for topic in ["/imu0", "~imu", "vio/imu_raw"]:
    out = os.path.join(work, "imu.yaml")
    run = subprocess.run(base + ["--export", "kalibr=" + out, "--kalibr-topic", topic],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    with open(out) as f:
        doc = yaml.safe_load(f)
    assert set(doc) == expected, sorted(doc)
    assert doc["rostopic"] == topic, doc["rostopic"]
    assert all(isinstance(doc[k], (int, float)) and not isinstance(doc[k], bool)
               for k in expected - {"rostopic"}), doc
    os.remove(out)

for topic in ["x\nupdate_rate: 1\nevil: true", "/imu0: {a: 1}", "imu #0", "", "/imu//0", "0imu"]:
    out = os.path.join(work, "evil.yaml")
    run = subprocess.run(base + ["--export", "kalibr=" + out, "--kalibr-topic", topic,
                                 "--json", os.path.join(work, "evil.json")],
                         capture_output=True, text=True)
    assert run.returncode == 2, (topic, run.returncode, run.stderr)
    assert "--kalibr-topic" in run.stderr and "not a ROS topic name" in run.stderr, run.stderr
    assert not os.path.exists(out) and not os.path.exists(os.path.join(work, "evil.json")), topic
print("every Kalibr export parsed back to its keys; 6 topics refused")
