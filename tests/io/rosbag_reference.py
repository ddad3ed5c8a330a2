#!/usr/bin/env python3
"""What Debian's python3-rosbag reads of ROS 1 bags, as JSON on stdout: per bag and
sensor_msgs/Imu topic, the message count and the first and last messages (header stamp, record
time, linear_acceleration, angular_velocity). tests/io/rosbag_real_test.cc compares plumb's
reader with it. Exit 77 when the rosbag module is absent."""
import json
import sys

try:
    import rosbag
except ImportError:
    sys.exit(77)


def sample(msg, t):
    return {
        "stamp": [msg.header.stamp.secs, msg.header.stamp.nsecs],
        "receive": [t.secs, t.nsecs],
        "acc": [msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z],
        "gyr": [msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z],
        "frame_id": msg.header.frame_id,
    }


out = {}
for path in sys.argv[1:]:
    topics = {}
    with rosbag.Bag(path) as bag:
        for topic, msg, t in bag.read_messages():
            if msg._type != "sensor_msgs/Imu":
                continue
            entry = topics.setdefault(topic, {"count": 0})
            entry["count"] += 1
            if "first" not in entry:
                entry["first"] = sample(msg, t)
            entry["last"] = sample(msg, t)
        counts = {k: v.message_count for k, v in bag.get_type_and_topic_info().topics.items()}
    out[path] = {"imu": topics, "messages": counts}
json.dump(out, sys.stdout)
