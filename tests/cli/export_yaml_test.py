#!/usr/bin/env python3
"""Issue 35 item 6: what plumb writes as YAML parses back, with a YAML parser, to exactly the
keys it wrote; a Kalibr topic that would add keys (a newline and "evil: true") is refused
before anything is written. Issue 38: a board's Kalibr IMU set parses, as Kalibr reads it
(yaml.safe_load), to a number for every value (YAML 1.1 reads "5e-05" as a string) and a 4x4
T_i_b whose rotation is the transpose of the IMU's rotation in plumb's JSON.

Usage: export_yaml_test.py PLUMB SOURCE_DIR WORK_DIR"""
import json
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
# A simulated board of three IMUs, calibrated together, exported as Kalibr's IMU set.
board, truth = os.path.join(work, "board.csv"), os.path.join(work, "truth.json")
site = ["--lat", "51.64", "--lon", "-1.2", "--height", "100"]
run = subprocess.run([plumb, "simulate", "--out", board, "--imus", "3", "--random-truth", "1",
                      "--poses", "16", "--rate", "100", "--seed", "5", "--truth-json", truth] + site,
                     capture_output=True, text=True)
assert run.returncode == 0, run.stderr
imu_set, cal = os.path.join(work, "imu_set.yaml"), os.path.join(work, "board.json")
run = subprocess.run([plumb, "calibrate", board, "--imus", "all", "--json", cal,
                      "--export", "kalibr=" + imu_set] + site, capture_output=True, text=True)
assert run.returncode == 0, run.stderr
with open(imu_set) as f:
    doc = yaml.safe_load(f)
with open(cal) as f:
    calibration = json.load(f)
assert sorted(doc) == ["imu0", "imu1", "imu2"], sorted(doc)
for k, imu in enumerate(calibration["imus"]):
    entry = doc["imu%d" % k]
    assert set(entry) == expected | {"T_i_b", "time_offset"}, sorted(entry)
    numbers = [entry[key] for key in expected - {"rostopic"}] + [entry["time_offset"]]
    assert all(isinstance(v, float) for v in numbers), entry
    assert all(v > 0 for v in numbers[:-1]), entry  # Kalibr refuses a noise value <= 0
    T = entry["T_i_b"]
    assert len(T) == 4 and all(len(row) == 4 for row in T), T
    assert all(isinstance(v, (int, float)) for row in T for v in row), T
    R = imu["rotation"]["matrix"]
    assert all(abs(T[i][j] - R[j][i]) < 1e-12 for i in range(3) for j in range(3)), (T, R)
print("every Kalibr export parsed back to its keys; 6 topics refused; a board's IMU set "
      "parsed to numbers and 4x4 T_i_b")
