"""The Python module's results equal the plumb command's on the same inputs, bit for bit (the
options the library's messages name spelled as each front end spells them): the
calibrate --json document (the tutorial's bundled session), its parameters, sigmas and
covariance, diagnose --json, apply's corrected samples, simulate's samples, and one point of a
study as `plumb sweep` writes it."""
import csv
import json
import os
import pickle
import shutil
import subprocess
import unittest

import numpy as np

import plumb

PLUMB = os.environ["PLUMB"]
SOURCE = os.environ["PLUMB_SOURCE_DIR"]
OUT = os.environ["PLUMB_TEST_OUT"]
# The session the tutorial and scripts/demo calibrate (docs/tutorial.md), as the command reads it.
SESSION = "data/mikoff/imu0.log"
TABLE = ["--columns", "ax,ay,az,gx,gy,gz", "--rate", "100"]


def run(*args):
    """The plumb command, from the repository root; its standard output."""
    done = subprocess.run([PLUMB, *args], cwd=SOURCE, capture_output=True, text=True)
    if done.returncode != 0:
        raise AssertionError(f"plumb {' '.join(args)} exited {done.returncode}: {done.stderr}")
    return done.stdout


# The options the library's messages name (core/option_name.h), as the command spells them and
# as this module does (python/bindings/keywords.cc): the documents are equal once these are.
SPELLINGS = [("(give --lat --lon --height)", "(give site=(lat_deg, lon_deg, height_m))"),
             ("(--heading DEG or --level-north)", "(heading=DEG or level_north=True)"),
             ("override with --accel-rw/--gyro-rw/--accel-bi/--gyro-bi",
              "override with accel_rw/gyro_rw/accel_bi/gyro_bi"),
             (" --noise-from a long still recording",
              " CalibrationOptions::other_still_noise a long still recording"),
             ("or --estimate-rw (from the session's holds", "or estimate_rw=True (from the session's holds"),
             ("(without --estimate-rw) or give the walk (--accel-rw/--gyro-rw)",
              "(without estimate_rw=True) or give the walk (accel_rw/gyro_rw)"),
             ("or --noise-from a long still recording) for sigmas",
              "or CalibrationOptions::other_still_noise a long still recording) for sigmas"),
             ("iterations (--max-iterations)", "iterations (max_iterations)")]


def in_python_words(text):
    """A document the command wrote, with the options its messages name spelled as Python's."""
    for cli, python in SPELLINGS:
        text = text.replace(cli, python)
    return text


def out(name):
    os.makedirs(OUT, exist_ok=True)
    return os.path.join(OUT, name)


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(x) for x in r] for r in rows[1:]])


class CliEqual(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        os.chdir(SOURCE)
        cls.session = plumb.open(SESSION, columns="ax,ay,az,gx,gy,gz", rate=100)

    def test_calibrate_document_is_the_commands(self):
        run("calibrate", SESSION, *TABLE, "--json", out("cal.json"))
        with open(out("cal.json")) as f:
            text = f.read()
        result = plumb.calibrate(self.session, model="base")
        self.assertEqual(result.to_json(), in_python_words(text))
        doc = json.loads(text)
        for p in doc["parameters"]:
            mine = result.parameters[p["name"]]
            self.assertEqual(mine.value, p["value"], p["name"])
            self.assertEqual(mine.sigma, p["sigma"], p["name"])
        self.assertEqual(result.parameter_names, doc["covariance"]["parameters"])
        np.testing.assert_array_equal(result.covariance, np.array(doc["covariance"]["matrix"]))
        self.assertEqual(result.observability, doc["observability"])

    def test_calibrate_with_site_and_options_is_the_commands(self):
        run("calibrate", SESSION, *TABLE, "--lat", "51.64", "--lon", "-1.2", "--height", "100",
            "--model", "base+gyro_g_sensitivity", "--constant-bias", "--json", out("cal_site.json"))
        result = plumb.calibrate(self.session, model="base+gyro_g_sensitivity",
                                 site=(51.64, -1.2, 100), constant_bias=True)
        with open(out("cal_site.json")) as f:
            self.assertEqual(result.to_json(), in_python_words(f.read()))

    def test_uniform_clock_is_the_commands(self):
        # A simulated session whose stamps a host wrote on arrival (late by 0.1 ms more each
        # sample, back every 25), calibrated on the uniform clock fitted through them.
        run("simulate", "--out", out("clock_sim.csv"), "--poses", "12", "--seed", "8")
        with open(out("clock_sim.csv")) as f:
            lines = f.read().splitlines()
        stamped = [lines[0]]
        for k, line in enumerate(lines[1:]):
            fields = line.split(",")
            fields[0] = repr(float(fields[0]) + 1e-4 * (k % 25))
            stamped.append(",".join(fields))
        with open(out("clock_host.csv"), "w") as f:
            f.write("\n".join(stamped) + "\n")
        run("calibrate", out("clock_host.csv"), "--clock", "uniform", "--json",
            out("clock_cal.json"))
        session = plumb.open(out("clock_host.csv"), clock="uniform")
        with open(out("clock_cal.json")) as f:
            self.assertEqual(plumb.calibrate(session).to_json(), in_python_words(f.read()))
        with self.assertRaises(plumb.Error):
            plumb.open(out("clock_host.csv"), clock="host")

    def test_ros_bag_is_the_commands(self):
        # A ROS bag's topic and its record times (--topic, --clock receive): the same fit.
        bag = os.path.join(os.environ.get("PLUMB_SHARED_DATA_DIR", ""), "ros", "ardrone_imu.bag")
        if not os.path.exists(bag):
            self.skipTest("shared data absent: " + bag)
        run("calibrate", bag, "--topic", "/ardrone/imu", "--clock", "receive", "--json",
            out("bag_cal.json"))
        session = plumb.open(bag, topic="/ardrone/imu", clock="receive")
        with open(out("bag_cal.json")) as f:
            self.assertEqual(plumb.calibrate(session).to_json(), in_python_words(f.read()))
        with self.assertRaises(plumb.Error) as raised:
            plumb.open(bag, topic="/nope")
        self.assertEqual(raised.exception.options, ("topic",))

    def test_datasheet_units_are_the_commands(self):
        # The bias wander levels in a datasheet's units, parsed by the command's parser.
        levels = {"gyro_bi": "4 deg/h", "accel_rw": "10 ug/sqrt(h)"}
        run("calibrate", SESSION, *TABLE, "--gyro-bi", levels["gyro_bi"], "--accel-rw",
            levels["accel_rw"], "--json", out("cal_levels.json"))
        result = plumb.calibrate(self.session, **levels)
        with open(out("cal_levels.json")) as f:
            self.assertEqual(result.to_json(), in_python_words(f.read()))
        # The same levels in SI, as numbers: the same fit (to the last bits of the conversion).
        deg_per_hour = np.pi / 180 / 3600
        si = plumb.calibrate(self.session, gyro_bi=4 * deg_per_hour,
                             accel_rw=10e-6 * 9.80665 / 60)
        for name, p in result.parameters.items():
            self.assertAlmostEqual(si.parameters[name].value, p.value, delta=1e-9 * abs(p.value))
            self.assertAlmostEqual(si.parameters[name].sigma, p.sigma, delta=1e-6 * p.sigma)
        # ... and not the fit without them (the levels reach the fit).
        default = plumb.calibrate(self.session)
        self.assertNotEqual(default.parameters["accel.bias.x"].sigma,
                            result.parameters["accel.bias.x"].sigma)

    def test_diagnose_document_is_the_commands(self):
        run("diagnose", SESSION, *TABLE, "--json", out("diagnosis.json"))
        with open(out("diagnosis.json")) as f:
            document = f.read()
        diagnosis = plumb.diagnose(self.session, model="base")
        self.assertEqual(diagnosis.to_json(), in_python_words(document))
        # The advice is the command's (issue 34: like with like), recommended or None.
        self.assertEqual(diagnosis.recommendation, json.loads(document)["recommendation"])

    def test_apply_equals_plumb_apply(self):
        run("calibrate", SESSION, *TABLE, "--json", out("cal_apply.json"))
        run("apply", out("cal_apply.json"), SESSION, *TABLE, "--out", out("corrected.csv"),
            "--sigma")
        header, table = read_csv(out("corrected.csv"))
        calibration = plumb.load_calibration(out("cal_apply.json"))
        f, w, fs, ws = calibration.apply(self.session, sigma=True)
        # plumb apply writes %.9g: round ours the same way to compare every printed digit.
        def printed(a):
            return np.array([[float(f"{x:.9g}") for x in row] for row in a])
        np.testing.assert_array_equal(printed(f), table[:, 1:4])
        np.testing.assert_array_equal(printed(w), table[:, 4:7])
        np.testing.assert_array_equal(printed(fs), table[:, 7:10])
        np.testing.assert_array_equal(printed(ws), table[:, 10:13])
        # The same samples given as arrays (float64, the session's values) and times.
        f2, w2 = calibration.apply(self.session.acc.astype(np.float64),
                                   self.session.gyr.astype(np.float64),
                                   time=self.session.time)
        np.testing.assert_array_equal(f2, f)
        np.testing.assert_array_equal(w2, w)

    def test_board_apply_equals_plumb_apply(self):
        # A board's IMU 2 (SPEC 6): load_calibration(imu=2) applies its own calibration into
        # the body frame, as plumb apply --imus writes its acc2_ columns.
        board = out("board_apply.csv")
        run("simulate", "--out", board, "--imus", "3", "--random-truth", "1", "--poses", "6",
            "--rate", "50", "--seed", "4")
        run("calibrate", board, "--imus", "all", "--json", out("board_apply.json"))
        run("apply", out("board_apply.json"), board, "--imus", "all", "--out",
            out("board_corrected.csv"), "--sigma")
        header, table = read_csv(out("board_corrected.csv"))
        imu2 = plumb.open(board, imus="all").other_imus[1]
        calibration = plumb.load_calibration(out("board_apply.json"), imu=2)
        self.assertEqual(calibration.imu, 2)
        self.assertIn("rotation.x", calibration.parameter_names)
        f, w, fs, ws = calibration.apply(imu2.acc, imu2.gyr, imu2.temp, time=imu2.time,
                                         sigma=True)
        def printed(a):
            return np.array([[float(f"{x:.9g}") for x in row] for row in a])
        def columns(*names):
            return table[:, [header.index(n) for n in names]]
        np.testing.assert_array_equal(printed(f), columns("acc2_x", "acc2_y", "acc2_z"))
        np.testing.assert_array_equal(printed(w), columns("gyr2_x", "gyr2_y", "gyr2_z"))
        np.testing.assert_array_equal(printed(fs), columns("acc2_x_sigma", "acc2_y_sigma",
                                                           "acc2_z_sigma"))
        # It pickles as IMU 2's; an IMU the board has not is named.
        self.assertEqual(pickle.loads(pickle.dumps(calibration)).imu, 2)
        with self.assertRaises(plumb.InputError) as raised:
            plumb.load_calibration(out("board_apply.json"), imu=5)
        self.assertIn("no calibration of IMU 5 (it calibrates IMU 0, 1, 2)", str(raised.exception))

    def test_simulate_equals_plumb_simulate(self):
        run("simulate", "--out", out("sim.csv"), "--random-truth", "1", "--poses", "6",
            "--lat", "51.64", "--lon", "-1.2", "--height", "100", "--seed", "3")
        sim = plumb.simulate(random_truth=1, poses=6, site=(51.64, -1.2, 100), seed=3)
        written = plumb.open(out("sim.csv"))
        np.testing.assert_array_equal(sim.session.time, written.time)
        np.testing.assert_array_equal(sim.session.acc, written.acc)
        np.testing.assert_array_equal(sim.session.gyr, written.gyr)
        np.testing.assert_array_equal(sim.session.temp, written.temp)

    def test_sweep_point_is_the_commands_point_file(self):
        study = {"name": "python test", "seed": 5, "runs": 2, "design": "grid",
                 "base": {"schedule": "multipose", "still_s": 3, "turn_s": 2, "rate_hz": 50,
                          "sensor": "typical", "random_truth": 1},
                 "fit": {"model": "base"},
                 "factors": [{"name": "poses", "levels": [6, 8]}]}
        path = out("study.json")
        with open(path, "w") as f:
            json.dump(study, f)
        shutil.rmtree(out("sweep"), ignore_errors=True)  # a rerun would resume an older run's
        run("sweep", path, "--out", out("sweep"), "--jobs", "1")
        self.assertEqual(plumb.sweep_points(path), 2)
        for index in range(2):
            with open(os.path.join(out("sweep"), "points", f"point-{index:05d}.json")) as f:
                text = f.read()
            self.assertEqual(plumb.sweep_point_json(path, index), text)
            self.assertEqual(plumb.sweep_point(study, index), json.loads(text))
        with open(os.path.join(out("sweep"), "study.json")) as f:
            self.assertEqual(plumb.study_json(path), f.read())

    def test_a_yaml_study_is_the_json_study(self):
        # As plumb sweep reads them: examples/studies/gravity.yaml is gravity.json in YAML.
        studies = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "studies")
        self.assertEqual(plumb.study_json(os.path.join(studies, "gravity.yaml")),
                         plumb.study_json(os.path.join(studies, "gravity.json")))


if __name__ == "__main__":
    unittest.main()
