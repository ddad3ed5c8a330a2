#!/usr/bin/env python3
"""Dumps the messages of ROS 1 bags as Debian's python3-rosbag reads them, as JSON on stdout:
per message its topic, the record (receive) time and, for sensor_msgs/Imu and
sensor_msgs/MagneticField, every field (floats as Python's json writes them: repr, the exact
double; NaN and the infinities as the strings "NaN", "Infinity", "-Infinity", which JSON has
no numbers for). make_ros2_fixtures.mjs writes the same messages as ROS 2 bags (MCAP, .db3).

  /usr/bin/python3 dump_ros1_bag.py BAG > messages.json

Exit 77 when the rosbag module is absent (Debian's python3-rosbag: use /usr/bin/python3)."""
import json
import math
import sys

try:
    import rosbag
except ImportError:
    sys.exit(77)


def header(h):
    return {"stamp": {"sec": h.stamp.secs, "nanosec": h.stamp.nsecs}, "frame_id": h.frame_id}


def number(x):
    return x if math.isfinite(x) else ("NaN" if math.isnan(x) else
                                       ("Infinity" if x > 0 else "-Infinity"))


def vec3(v):
    return {"x": number(v.x), "y": number(v.y), "z": number(v.z)}


def floats(values):
    return [number(x) for x in values]


def fields(msg):
    if msg._type == "sensor_msgs/Imu":
        o = msg.orientation
        return {
            "header": header(msg.header),
            "orientation": {"x": number(o.x), "y": number(o.y), "z": number(o.z), "w": number(o.w)},
            "orientation_covariance": floats(msg.orientation_covariance),
            "angular_velocity": vec3(msg.angular_velocity),
            "angular_velocity_covariance": floats(msg.angular_velocity_covariance),
            "linear_acceleration": vec3(msg.linear_acceleration),
            "linear_acceleration_covariance": floats(msg.linear_acceleration_covariance),
        }
    if msg._type == "sensor_msgs/MagneticField":
        return {
            "header": header(msg.header),
            "magnetic_field": vec3(msg.magnetic_field),
            "magnetic_field_covariance": floats(msg.magnetic_field_covariance),
        }
    raise SystemExit("dump_ros1_bag.py: no ROS 2 form for " + msg._type)


messages = []
with rosbag.Bag(sys.argv[1]) as bag:
    for topic, msg, t in bag.read_messages():
        messages.append({"topic": topic, "type": msg._type,
                         "receive": {"sec": t.secs, "nsec": t.nsecs}, "msg": fields(msg)})
json.dump({"source": sys.argv[1], "messages": messages}, sys.stdout)
