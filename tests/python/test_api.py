"""The Python module's contract apart from the command: errors are plumb.Error naming the file,
never a crash; the session's arrays are views over its storage; apply takes arrays; keywords
are checked."""
import gc
import os
import unittest

import numpy as np

import plumb

SOURCE = os.environ["PLUMB_SOURCE_DIR"]
OUT = os.environ["PLUMB_TEST_OUT"]
SESSION = os.path.join(SOURCE, "data/mikoff/imu0.log")


def out(name):
    os.makedirs(OUT, exist_ok=True)
    return os.path.join(OUT, name)


class Errors(unittest.TestCase):
    def test_error_is_an_exception_class(self):
        self.assertTrue(issubclass(plumb.Error, Exception))
        self.assertTrue(issubclass(plumb.InputError, plumb.Error))
        self.assertTrue(issubclass(plumb.InsufficientDataError, plumb.Error))

    def test_missing_file_names_it(self):
        with self.assertRaises(plumb.InputError) as c:
            plumb.open(out("absent.csv"))
        self.assertIn("absent.csv", str(c.exception))
        self.assertEqual(c.exception.file, out("absent.csv"))

    def test_bad_table_line_names_file_and_line(self):
        path = out("bad.csv")
        with open(path, "w") as f:
            f.write("1,2,3\n4,x,6\n")
        with self.assertRaises(plumb.Error) as c:
            plumb.open(path, columns="ax,ay,az", rate=10)
        self.assertIn("bad.csv:line 2", str(c.exception))

    def test_not_native_says_how_to_describe_it(self):
        with self.assertRaises(plumb.InputError) as c:
            plumb.open(SESSION)
        self.assertIn("columns=", str(c.exception))

    def test_malformed_options_are_errors(self):
        # The library's parsers name the keyword as Python spells it, never the command's flag.
        for kwargs, text in [({"columns": "ax,ay", "rate": 10},
                              "open: columns 'ax,ay' must name all three accelerometer"),
                             ({"columns": "ax,ay,az"},
                              "open: columns 'ax,ay,az' has no time column (t): give rate=HZ"),
                             ({"columns": "ax,ay,az,gx,gy,gz", "rate": 100, "axis_map": "1,2"},
                              "open: axis_map must be three signed axes such as 1,-2,-3 (got '1,2')"),
                             ({"columns": "ax,ay,az", "rate": 100, "acc_unit": "furlong"},
                              "open: acc_unit must be m/s^2, g or counts (got 'furlong')"),
                             ({"columns": "ax,ay,az", "rate": 100, "delimiter": "|"},
                              "open: delimiter must be one of"),
                             ({"colums": "ax,ay,az"}, "unknown option(s) colums"),
                             ({"rate": "fast"}, "wrong type")]:
            with self.assertRaises(plumb.Error, msg=str(kwargs)) as c:
                plumb.open(SESSION, **kwargs)
            self.assertIn(text, str(c.exception))
            self.assertNotIn("--", str(c.exception))

    def test_bad_model_and_site(self):
        s = plumb.open(SESSION, columns="ax,ay,az,gx,gy,gz", rate=100)
        with self.assertRaises(plumb.Error):
            plumb.calibrate(s, model="base+no_such_effect")
        with self.assertRaises(plumb.Error):
            plumb.calibrate(s, site=(95.0, 0.0))
        with self.assertRaises(plumb.Error):
            plumb.calibrate(s, site="Oxford")

    def test_errors_name_the_keyword(self):
        s = plumb.open(SESSION, columns="ax,ay,az,gx,gy,gz", rate=100)
        for kwargs, text in [({"accel_bi": "4 deg/h"},
                              "calibrate: accel_bi: unit 'deg/h' not known here; use one of "
                              "m/s^2, ug, mg"),
                             ({"gyro_rw": -1.0}, "calibrate: gyro_rw: must be a finite number >= 0"),
                             ({"gyro_bi": [1]}, "calibrate: gyro_bi must be a number or a text")]:
            with self.assertRaises(plumb.Error, msg=str(kwargs)) as c:
                plumb.calibrate(s, **kwargs)
            self.assertIn(text, str(c.exception))
        for kwargs, text in [({"schedule": "paper-static", "poses": 3},
                              "simulate: poses applies to schedule multipose only"),
                             ({"schedule": "paper-static", "turn_s": 1.0},
                              "simulate: turn_s does not apply to schedule paper-static"),
                             ({"schedule": "spin"}, "simulate: schedule must be multipose")]:
            with self.assertRaises(plumb.Error, msg=str(kwargs)) as c:
                plumb.simulate(**kwargs)
            self.assertIn(text, str(c.exception))

    def test_messages_name_options_as_keywords(self):
        # Issue 36 item 3: the library's errors and gates name an option by meaning; Python
        # spells it as its keyword, never as the command's flag.
        path = out("nan.csv")
        with open(path, "w") as f:
            f.write("0,0,0,9.8\n0.01,nan,0,9.8\n")
        with self.assertRaises(plumb.InputError) as c:
            plumb.open(path, columns="t,ax,ay,az")
        self.assertIn("(to skip such rows: drop_nan=True)", str(c.exception))
        self.assertNotIn("--", str(c.exception))
        # ... and carry the option as data, as the keyword.
        self.assertEqual(c.exception.options, ("drop_nan",))
        self.assertEqual(c.exception.option, "drop_nan")
        s = plumb.open(SESSION, columns="ax,ay,az,gx,gy,gz", rate=100)
        fit = plumb.calibrate(s, max_iterations=1).fit
        gates = {g["name"]: g["message"] for g in fit["gates"]}
        self.assertIn("allow more iterations (max_iterations)", gates["not_converged"])
        self.assertNotIn("--", gates["not_converged"])
        options = {g["name"]: g["options"] for g in fit["gates"]}
        self.assertEqual(options["not_converged"], ("max_iterations",))
        # An error whose message names no option carries none.
        with self.assertRaises(plumb.InputError) as c:
            plumb.open(out("missing.csv"))
        self.assertEqual(c.exception.options, ())
        self.assertIsNone(c.exception.option)

    def test_warnings_carry_a_code_and_their_options(self):
        # The warnings stay strings; .notices gives each its stable code and its options, as
        # keywords, in the same order.
        path = out("nan_dropped.csv")
        with open(path, "w") as f:
            f.write("0,0,0,9.8\n0.01,nan,0,9.8\n0.02,0,0,9.8\n0.03,0,0,9.8\n")
        s = plumb.open(path, columns="t,ax,ay,az", drop_nan=True)
        self.assertTrue(all(isinstance(w, str) for w in s.warnings))
        self.assertEqual([n["message"] for n in s.notices], s.warnings)
        self.assertIn("nan_rows_skipped", [n["code"] for n in s.notices])
        r = plumb.calibrate(plumb.open(SESSION, columns="ax,ay,az,gx,gy,gz", rate=100),
                            max_iterations=1)
        self.assertTrue(all(isinstance(w, str) for w in r.warnings))
        self.assertEqual([n["message"] for n in r.notices], r.warnings)
        site = [n for n in r.notices if n["code"] == "site_unknown"]
        self.assertEqual(len(site), 1)
        self.assertEqual(site[0]["options"], ("site=(lat_deg, lon_deg, height_m)",))
        self.assertIn("(give site=(lat_deg, lon_deg, height_m))", site[0]["message"])

    def test_bad_calibration_file_names_it(self):
        path = out("not_a_calibration.json")
        with open(path, "w") as f:
            f.write('{"model": "base"')
        with self.assertRaises(plumb.InputError) as c:
            plumb.load_calibration(path)
        self.assertIn("not_a_calibration.json", str(c.exception))

    def test_bad_arrays_are_errors(self):
        s = plumb.open(SESSION, columns="ax,ay,az,gx,gy,gz", rate=100)
        plumb.calibrate(s).save(out("cal.json"))
        cal = plumb.load_calibration(out("cal.json"))
        with self.assertRaises(plumb.Error):
            cal.apply(np.zeros((5, 2)), np.zeros((5, 3)))
        with self.assertRaises(plumb.Error):
            cal.apply(np.zeros((5, 3)), np.zeros((4, 3)))
        with self.assertRaises(plumb.Error):  # a gyroscope model without gyroscope samples
            cal.apply(np.zeros((5, 3)))


class VehicleMotion(unittest.TestCase):
    COPTER = os.path.join(SOURCE, "../shared/data/ardupilot/copter344_pixhawk1_oldformat.bin")

    def test_a_text_table_says_nothing_of_flight(self):
        s = plumb.open(SESSION, columns="ax,ay,az,gx,gy,gz", rate=100)
        self.assertEqual(s.vehicle_motion, [])

    def test_a_flight_log_says_where_the_vehicle_flew(self):
        if not os.path.exists(self.COPTER):
            self.skipTest("shared data absent: " + self.COPTER)
        s = plumb.open(self.COPTER)
        air = [m for m in s.vehicle_motion if m["evidence"] == "airborne"]
        self.assertEqual(len(air), 1)
        self.assertAlmostEqual(air[0]["t_begin_s"], 228.075573, places=5)
        self.assertAlmostEqual(air[0]["t_end_s"], 375.270177, places=5)
        self.assertEqual(air[0]["source"], "EV NOT_LANDED .. LAND_COMPLETE")
        gps = [m for m in s.vehicle_motion if m["evidence"] == "gps_moving"]
        self.assertGreater(len(gps), 0)
        self.assertAlmostEqual(max(m["max_ground_speed_m_s"] for m in gps), 5.602, places=3)


class Arrays(unittest.TestCase):
    def test_session_arrays_are_views_of_one_storage(self):
        s = plumb.open(SESSION, columns="ax,ay,az,gx,gy,gz", rate=100)
        a, b = s.acc, s.acc
        self.assertTrue(np.shares_memory(a, b))
        self.assertFalse(a.flags.owndata)
        self.assertFalse(a.flags.writeable)
        self.assertEqual(a.shape, (len(s), 3))
        self.assertTrue(np.shares_memory(s.time, s.time))
        self.assertTrue(np.shares_memory(s.gyr, s.gyr))

    def test_a_view_keeps_its_session_alive(self):
        f = plumb.open(SESSION, columns="ax,ay,az,gx,gy,gz", rate=100).acc
        first = f[0].copy()
        gc.collect()
        junk = [np.ones(1000) for _ in range(1000)]
        del junk
        np.testing.assert_array_equal(f[0], first)

    def test_apply_to_the_session_equals_apply_to_its_arrays(self):
        s = plumb.open(SESSION, columns="ax,ay,az,gx,gy,gz", rate=100)
        plumb.calibrate(s).save(out("cal_arrays.json"))
        cal = plumb.load_calibration(out("cal_arrays.json"))
        f, w = cal.apply(s)
        f2, w2 = cal.apply(s.acc, s.gyr, time=s.time)
        np.testing.assert_array_equal(f, f2)
        np.testing.assert_array_equal(w, w2)
        self.assertEqual(f.shape, (len(s), 3))
        # The base model has no time or angular-acceleration effect: times are not needed.
        f3, _ = cal.apply(s.acc, s.gyr)
        np.testing.assert_array_equal(f, f3)


class Ros2Bags(unittest.TestCase):
    # plumb.open recognises ROS 2 bags by content, as the command does: the small MCAP and .db3
    # seeds of tests/fuzz (60 messages of a real ROS 1 recording, written by an independent
    # writer) give the same arrays, bit for bit, as the ROS 1 original.
    def test_mcap_and_db3_open_like_the_ros1_bag(self):
        seeds = os.path.join(SOURCE, "tests/fuzz/seeds")
        ref = plumb.open(os.path.join(seeds, "rosbag/phidgets_60_none.bag"))
        for name in ["mcap/phidgets_60.mcap", "mcap/phidgets_60_zstd.mcap",
                     "mcap/phidgets_60_lz4.mcap", "db3/phidgets_60.db3"]:
            with self.subTest(name):
                s = plumb.open(os.path.join(seeds, name))
                self.assertEqual(len(s), 30)
                for a in ["time", "specific_force", "rate"]:
                    self.assertTrue(np.array_equal(getattr(s, a), getattr(ref, a)), a)
                with self.assertRaises(plumb.InputError):
                    plumb.open(os.path.join(seeds, name), topic="/nope")


class Docstrings(unittest.TestCase):
    def test_every_function_and_property_has_one(self):
        for name in plumb.__all__:
            obj = getattr(plumb, name)
            self.assertTrue(obj.__doc__ and obj.__doc__.strip(), name)
            if isinstance(obj, type) and not issubclass(obj, BaseException):
                for attr, value in vars(obj).items():
                    if attr.startswith("_"):
                        continue
                    self.assertTrue(value.__doc__ and value.__doc__.strip(), f"{name}.{attr}")


if __name__ == "__main__":
    unittest.main()
