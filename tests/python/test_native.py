"""Python that feels native (issue 37 part 2): sessions from arrays and DataFrames, a Result's
calibration applied without a file, values and sigmas as arrays, names that do not clash, units
in apply, warnings through the warnings module, errors that are ValueError / FileNotFoundError,
stubs, reprs, pickling, open out of __all__, messages in Python's words."""
import ast
import errno
import os
import pickle
import unittest
import warnings

import numpy as np

import plumb

SOURCE = os.environ["PLUMB_SOURCE_DIR"]
OUT = os.environ["PLUMB_TEST_OUT"]
SESSION = os.path.join(SOURCE, "data/mikoff/imu0.log")
G0 = 9.80665


def out(name):
    os.makedirs(OUT, exist_ok=True)
    return os.path.join(OUT, name)


def open_session():
    return plumb.open(SESSION, columns="ax,ay,az,gx,gy,gz", rate=100)


def quietly(function, *args, **kwargs):
    """function(*args, **kwargs) with plumb's warnings not shown (tests that check them say so)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", plumb.PlumbWarning)
        return function(*args, **kwargs)


_cache = {}


def mikoff():
    """The bundled session and its base calibration, made once."""
    if not _cache:
        _cache["session"] = open_session()
        _cache["result"] = quietly(plumb.calibrate, _cache["session"])
    return _cache["session"], _cache["result"]


class FromArrays(unittest.TestCase):
    def test_same_samples_same_session_same_result(self):
        s, r = mikoff()
        a = plumb.Session.from_arrays(s.time, s.acc, s.gyr, source=SESSION)
        np.testing.assert_array_equal(a.time, s.time)
        np.testing.assert_array_equal(a.acc, s.acc)
        np.testing.assert_array_equal(a.gyr, s.gyr)
        self.assertIsNone(a.temp)
        self.assertEqual((a.acc.dtype, a.time.dtype), (np.float32, np.float64))
        self.assertEqual((a.source, a.inputs, a.warnings), (SESSION, [SESSION], []))
        # Still segmentation happens in calibrate, as for the file: the same document.
        self.assertEqual(quietly(plumb.calibrate, a).to_json(), r.to_json())

    def test_lists_and_float32_are_taken(self):
        t = [0.0, 0.01, 0.02]
        acc = [[0.0, 0.0, -9.8]] * 3
        s = plumb.Session.from_arrays(t, np.array(acc, dtype=np.float32), temp=[20, 20, 21])
        self.assertEqual(len(s), 3)
        self.assertFalse(s.has_gyro)
        np.testing.assert_array_equal(s.temp, np.array([20, 20, 21], dtype=np.float32))

    def test_units_are_converted_as_open_converts_them(self):
        s, _ = mikoff()
        acc_g = s.acc.astype(np.float64) / G0
        gyr_deg = np.degrees(s.gyr.astype(np.float64))
        a = plumb.Session.from_arrays(s.time, acc_g, gyr_deg, acc_unit="g", gyr_unit="deg/s")
        np.testing.assert_array_equal(a.acc, (acc_g * G0).astype(np.float32))
        np.testing.assert_array_equal(a.gyr, (gyr_deg * (np.pi / 180)).astype(np.float32))
        np.testing.assert_allclose(a.acc, s.acc, rtol=1e-6)
        c = plumb.Session.from_arrays(s.time, s.acc, s.gyr, acc_unit="counts", gyr_unit="counts")
        self.assertEqual((c.acc_unit, c.gyr_unit), ("counts", "counts"))
        with self.assertRaises(plumb.Error) as e:
            plumb.Session.from_arrays(s.time, s.acc, acc_unit="furlong")
        self.assertIn("acc_unit must be m/s^2, g or counts", str(e.exception))

    def test_errors_name_the_argument_and_the_row(self):
        t = np.arange(10) * 0.01
        acc = np.tile([0.0, 0.0, -9.8], (10, 1))
        gyr = np.zeros((10, 3))
        bad = acc.copy()
        bad[3, 1] = np.nan
        with self.assertRaises(plumb.InputError) as e:
            plumb.Session.from_arrays(t, bad, gyr)
        self.assertEqual(e.exception.where, "acc row 3")
        self.assertIn("arrays:acc row 3: NaN or infinite value", str(e.exception))
        self.assertIn("(to skip such rows: drop_nan=True)", str(e.exception))
        self.assertEqual(e.exception.options, ("drop_nan",))
        self.assertIsInstance(e.exception, ValueError)
        back = t.copy()
        back[5] = back[4]
        with self.assertRaises(plumb.InputError) as e:
            plumb.Session.from_arrays(back, acc, gyr)
        self.assertIn("time row 5", str(e.exception))
        self.assertIn("repeats the previous row's", str(e.exception))
        for args, text in [((t, acc[:, :2], gyr), "acc must be N x 3 numbers (shape (N, 3)), got shape (10, 2)"),
                           ((t, acc, gyr[:9]), "gyr has 9 rows, time 10"),
                           ((t.reshape(2, 5), acc, gyr), "time must be N numbers"),
                           ((t, acc, gyr, np.ones(4)), "temp has 4 rows"),
                           ((t[:1], acc[:1]), "1 sample(s); at least 2 are needed")]:
            with self.assertRaises(plumb.InputError, msg=text) as e:
                plumb.Session.from_arrays(*args)
            self.assertIn(text, str(e.exception))
            self.assertNotIn("--", str(e.exception))

    def test_drop_nan_skips_rows_with_a_warning(self):
        t = np.arange(10) * 0.01
        acc = np.tile([0.0, 0.0, -9.8], (10, 1))
        acc[2, 0] = np.inf
        with self.assertWarns(plumb.PlumbWarning) as w:
            s = plumb.Session.from_arrays(t, acc, drop_nan=True)
        self.assertEqual(len(s), 9)
        self.assertEqual(w.warning.code, "nan_rows_skipped")
        self.assertIn("first at acc row 2", str(w.warning))
        self.assertEqual([n["code"] for n in s.notices], ["nan_rows_skipped"])


class FromDataFrame(unittest.TestCase):
    def setUp(self):
        try:
            import pandas  # noqa: F401
        except ImportError:
            self.skipTest("pandas is not installed (scripts/setup installs python3-pandas)")

    def test_columns_by_name(self):
        import pandas as pd
        s, _ = mikoff()
        df = pd.DataFrame({"time": s.time, "ax": s.acc[:, 0], "ay": s.acc[:, 1],
                           "az": s.acc[:, 2], "gx": s.gyr[:, 0], "gy": s.gyr[:, 1],
                           "gz": s.gyr[:, 2]})
        d = plumb.Session.from_dataframe(df)
        np.testing.assert_array_equal(d.time, s.time)
        np.testing.assert_array_equal(d.acc, s.acc)
        np.testing.assert_array_equal(d.gyr, s.gyr)
        self.assertEqual(d.source, "DataFrame")
        renamed = df.rename(columns={"ax": "acc_x", "ay": "acc_y", "az": "acc_z", "time": "t"})
        e = plumb.Session.from_dataframe(renamed, time="t", acc=("acc_x", "acc_y", "acc_z"),
                                         gyr=None)
        np.testing.assert_array_equal(e.acc, s.acc)
        self.assertFalse(e.has_gyro)
        by_index = plumb.Session.from_dataframe(df.set_index("time"), time=None)
        np.testing.assert_array_equal(by_index.time, s.time)

    def test_a_missing_column_names_the_argument(self):
        import pandas as pd
        df = pd.DataFrame({"time": [0.0, 0.1], "ax": [0.0, 0.0], "ay": [0.0, 0.0], "az": [9.8, 9.8]})
        with self.assertRaises(plumb.InputError) as e:
            plumb.Session.from_dataframe(df)
        self.assertIn("gyr: no column 'gx'", str(e.exception))
        with self.assertRaises(TypeError):
            plumb.Session.from_dataframe({"time": [0.0]})


class ResultCalibration(unittest.TestCase):
    def test_applies_bit_for_bit_as_the_saved_file(self):
        s, r = mikoff()
        r.save(out("native_cal.json"))
        loaded = plumb.load_calibration(out("native_cal.json"))
        self.assertIs(type(r.calibration), type(loaded))
        f1, w1 = r.calibration.apply(s.acc, s.gyr)
        f2, w2 = loaded.apply(s.acc, s.gyr)
        np.testing.assert_array_equal(f1, f2)
        np.testing.assert_array_equal(w1, w2)
        self.assertEqual(r.calibration.parameters, loaded.parameters)
        np.testing.assert_array_equal(r.calibration.covariance, loaded.covariance)
        f3, w3 = r.calibration.apply(s)
        np.testing.assert_array_equal(f1, f3)

    def test_values_and_sigmas_are_arrays_over_parameter_names(self):
        _, r = mikoff()
        names = r.parameter_names
        self.assertEqual(r.values.shape, (len(names),))
        self.assertEqual(r.sigmas.shape, (len(names),))
        for i, name in enumerate(names):
            self.assertEqual(r.values[i], r.parameters[name].value)
            self.assertEqual(r.sigmas[i], r.parameters[name].sigma)
        np.testing.assert_allclose(r.sigmas, np.sqrt(np.diag(r.covariance)), rtol=1e-9)

    def test_the_null_space_as_an_array(self):
        _, r = mikoff()  # everything observable
        self.assertEqual(r.null_space.shape, (0, len(r.null_space_names)))
        sim = plumb.simulate(poses=3, seed=2)
        u = quietly(plumb.calibrate, sim.session)
        k = len(u.observability["unobservable"])
        self.assertGreater(k, 0)
        self.assertEqual(u.null_space.shape, (k, len(u.null_space_names)))
        for row, text in zip(u.null_space, u.observability["unobservable"]):
            named = [u.null_space_names[j] for j in np.flatnonzero(np.abs(row) > 1e-9 * np.abs(row).max())]
            for name in named:
                self.assertIn(name, text)


class Names(unittest.TestCase):
    def test_new_names_and_deprecated_aliases(self):
        s, _ = mikoff()
        for old, new in [("specific_force", "acc"), ("rate", "gyr")]:
            with self.assertWarns(DeprecationWarning) as w:
                value = getattr(s, old)
            self.assertIn(f"use Session.{new}", str(w.warning))
            self.assertTrue(np.shares_memory(value, getattr(s, new)))
        with self.assertWarns(DeprecationWarning):
            self.assertTrue(np.isnan(s.temperature).all())
        self.assertIsNone(s.temp)

    def test_open_is_not_in_all(self):
        self.assertNotIn("open", plumb.__all__)
        self.assertTrue(callable(plumb.open))
        namespace = {}
        exec("from plumb import *", namespace)
        self.assertNotIn("open", namespace)
        for name in plumb.__all__:
            self.assertTrue(hasattr(plumb, name), name)


class ApplyUnits(unittest.TestCase):
    def test_units_in_and_out(self):
        s, r = mikoff()
        cal = r.calibration
        f, w = cal.apply(s.acc, s.gyr)
        acc_g = s.acc.astype(np.float64) / G0
        gyr_deg = np.degrees(s.gyr.astype(np.float64))
        fg, wd = cal.apply(acc_g, gyr_deg, acc_unit="g", gyr_unit="deg/s")
        np.testing.assert_allclose(fg * G0, f, rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(np.radians(wd), w, rtol=1e-6, atol=1e-8)
        # The SPEC's positional form still works; the defaults are SI.
        f2, w2 = cal.apply(s.acc, s.gyr, None)
        np.testing.assert_array_equal(f, f2)
        with self.assertRaises(plumb.Error) as e:
            cal.apply(s.acc, s.gyr, acc_unit="counts")
        self.assertIn("acc_unit='counts' but the calibration's accelerometer is in m/s^2", str(e.exception))
        with self.assertRaises(plumb.Error):
            cal.apply(s.acc, s.gyr, gyr_unit="rpm")
        with self.assertRaises(plumb.Error):
            cal.apply(s, acc_unit="g")


class Warnings(unittest.TestCase):
    def test_session_fit_and_diagnosis_warn(self):
        self.assertTrue(issubclass(plumb.PlumbWarning, UserWarning))
        path = out("native_nan.csv")
        with open(path, "w") as f:
            f.write("0,0,0,9.8\n0.01,nan,0,9.8\n0.02,0,0,9.8\n0.03,0,0,9.8\n")
        with self.assertWarns(plumb.PlumbWarning) as w:
            plumb.open(path, columns="t,ax,ay,az", drop_nan=True)
        self.assertEqual(w.warning.code, "nan_rows_skipped")
        s = open_session()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r = plumb.calibrate(s)
        codes = [c.message.code for c in caught if issubclass(c.category, plumb.PlumbWarning)]
        self.assertEqual(codes, [n["code"] for n in r.notices])
        self.assertIn("site_unknown", codes)
        site = [c.message for c in caught if c.message.code == "site_unknown"][0]
        self.assertEqual(site.options, ("site=(lat_deg, lon_deg, height_m)",))
        self.assertEqual(os.path.basename(caught[0].filename), "test_native.py")
        with self.assertWarns(plumb.PlumbWarning):
            plumb.diagnose(s, confirm=0)
        with warnings.catch_warnings():
            warnings.simplefilter("error", plumb.PlumbWarning)
            with self.assertRaises(plumb.PlumbWarning):
                plumb.calibrate(s)


class Errors(unittest.TestCase):
    def test_error_is_a_value_error(self):
        for cls in [plumb.Error, plumb.InputError, plumb.InsufficientDataError]:
            self.assertTrue(issubclass(cls, ValueError), cls)
            self.assertTrue(issubclass(cls, plumb.Error), cls)
        with self.assertRaises(ValueError):
            open_session().__class__.from_arrays([0.0, 1.0], [[0, 0]])

    def test_a_missing_file_is_file_not_found(self):
        for call in [lambda p: plumb.open(p), lambda p: plumb.load_calibration(p),
                     lambda p: plumb.open([SESSION, p], columns="ax,ay,az", rate=10)]:
            path = out("native_absent.csv")
            with self.assertRaises(FileNotFoundError) as e:
                call(path)
            self.assertEqual(e.exception.errno, errno.ENOENT)
            self.assertEqual(e.exception.filename, path)
            self.assertIsInstance(e.exception, plumb.InputError)
            self.assertEqual(e.exception.file, path)
            self.assertIn("native_absent.csv", str(e.exception))

    def test_messages_name_keywords(self):
        path = out("native_nan_error.csv")
        with open(path, "w") as f:
            f.write("0,0,0,9.8\n0.01,nan,0,9.8\n")
        with self.assertRaises(plumb.InputError) as e:
            plumb.open(path, columns="t,ax,ay,az")
        self.assertIn("(to skip such rows: drop_nan=True)", str(e.exception))
        s, _ = mikoff()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            plumb.calibrate(s, site=(51.6, -1.2, 100), gravity=9.81)
        gravity = [c.message for c in caught if c.message.code == "gravity_fixed"]
        self.assertEqual(len(gravity), 1)
        self.assertIn("by gravity instead of WGS84", str(gravity[0]))
        self.assertEqual(gravity[0].options, ("gravity",))
        with self.assertRaises(plumb.Error) as e:
            plumb.calibrate(s, level_north=True, heading=10.0)
        self.assertEqual(str(e.exception), "level_north excludes heading")
        with self.assertRaises(plumb.Error) as e:
            plumb.calibrate(s, max_iterations=0)
        self.assertIn("max_iterations must be >= 1", str(e.exception))
        for text in [str(e.exception)]:
            self.assertNotIn("--", text)


class Reprs(unittest.TestCase):
    def test_calibration_and_diagnosis(self):
        s, r = mikoff()
        text = repr(r.calibration)
        self.assertTrue(text.startswith("<plumb.Calibration base from <plumb.Result>: "), text)
        self.assertIn(f"{len(r.calibration.parameters)} parameters", text)
        self.assertIn(f"{len(r.parameter_names)} with covariance", text)
        d = quietly(plumb.diagnose, s, confirm=0)
        text = repr(d)
        self.assertTrue(text.startswith("<plumb.Diagnosis base: chi2/dof "), text)
        self.assertIn(f"{len(d.candidates)} candidates", text)
        self.assertIn("recommendation: ", text)


class Pickling(unittest.TestCase):
    def test_session_round_trip(self):
        s, r = mikoff()
        u = pickle.loads(pickle.dumps(s))
        for name in ["time", "acc", "gyr"]:
            np.testing.assert_array_equal(getattr(u, name), getattr(s, name))
            self.assertEqual(getattr(u, name).dtype, getattr(s, name).dtype)
        for name in ["source", "inputs", "warnings", "notices", "site", "acc_unit", "gyr_unit",
                     "firmware_left", "log_params", "vehicle_motion"]:
            self.assertEqual(getattr(u, name), getattr(s, name), name)
        self.assertEqual(quietly(plumb.calibrate, u).to_json(), r.to_json())

    def test_a_flight_log_session_round_trips(self):
        path = os.path.join(SOURCE, "../shared/data/ardupilot/copter344_pixhawk1_oldformat.bin")
        if not os.path.exists(path):
            self.skipTest("shared data absent: " + path)
        s = quietly(plumb.open, path)
        u = pickle.loads(pickle.dumps(s))
        for name in ["source", "warnings", "notices", "site", "firmware_left", "log_params",
                     "vehicle_motion", "has_temperature"]:
            self.assertEqual(getattr(u, name), getattr(s, name), name)
        np.testing.assert_array_equal(u.temp, s.temp)

    def test_a_boards_device_ids_round_trip(self):
        # PX4's exports find each IMU's calibration slot by its sensors' device ids: a pickled
        # session keeps them, IMU 0's and every other IMU's (vehicle_imu accel/gyro_device_id).
        path = os.path.join(SOURCE, "../shared/data/px4/sample_log_small.ulg")
        if not os.path.exists(path):
            self.skipTest("shared data absent: " + path)
        s = quietly(plumb.open, path, imus="all")
        state = pickle.loads(pickle.dumps(s)).__getstate__()
        self.assertEqual(state["device_ids"], (2424842.0, 2424842.0))
        self.assertEqual([b["device_ids"] for b in state["other_imus"]],
                         [(3670050.0, 3670050.0), (2621474.0, 2621474.0)])

    def test_the_boards_other_imus_are_exposed_and_round_trip(self):
        # A native CSV with IMU 1 (accelerometer, gyroscope, temperature) and IMU 2
        # (accelerometer only) on IMU 0's time column (SPEC 6, "Several IMUs of one board").
        path = out("board.csv")
        with open(path, "w") as f:
            f.write("time_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,acc1_x,acc1_y,acc1_z,"
                    "gyr1_x,gyr1_y,gyr1_z,temp1_c,acc2_x,acc2_y,acc2_z\n")
            for i in range(5):
                f.write(f"{0.01 * i},0.1,0.2,-9.8,0.001,0.002,0.003,"
                        f"{i},0.5,-9.75,0.01,0.02,{0.03 * i},30.25,4,5,-9.5\n")
        self.assertEqual(plumb.open(path).other_imus, [])  # IMU 0 alone unless imus= asks
        self.assertEqual([b.instance for b in plumb.open(path, imus=[0, 2]).other_imus], [2])
        s = plumb.open(path, imus="all")
        self.assertEqual(len(s), 5)
        imus = s.other_imus
        self.assertEqual([(b.instance, b.name, len(b)) for b in imus],
                         [(1, "acc1_x..", 5), (2, "acc2_x..", 5)])
        self.assertIsInstance(imus[0], plumb.BoardImu)
        np.testing.assert_array_equal(imus[0].acc[:, 0], np.arange(5, dtype=np.float32))
        np.testing.assert_array_equal(imus[0].temp, np.full(5, 30.25, dtype=np.float32))
        np.testing.assert_array_equal(imus[0].time, s.time)
        self.assertTrue(imus[0].has_gyro)
        self.assertFalse(imus[1].has_gyro)
        self.assertEqual(imus[1].gyr.shape, (0, 3))
        self.assertIsNone(imus[1].temp)
        self.assertEqual(imus[1].firmware_left, [])
        self.assertFalse(imus[0].acc.flags.writeable)
        acc = imus[0].acc
        del s, imus  # the view keeps the session's storage alive
        np.testing.assert_array_equal(acc[:, 0], np.arange(5, dtype=np.float32))
        s = plumb.open(path, imus="all")
        u = pickle.loads(pickle.dumps(s))
        self.assertEqual(len(u.other_imus), 2)
        for a, b in zip(u.other_imus, s.other_imus):
            self.assertEqual((a.instance, a.name, a.firmware_left, a.acc_unit, a.gyr_unit),
                             (b.instance, b.name, b.firmware_left, b.acc_unit, b.gyr_unit))
            for name in ["time", "acc", "gyr"]:
                np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
                self.assertEqual(getattr(a, name).dtype, getattr(b, name).dtype)
            self.assertEqual(a.temp is None, b.temp is None)
        np.testing.assert_array_equal(u.other_imus[0].temp, s.other_imus[0].temp)
        # Written back, the unpickled session reads as the file did.
        again = out("board_again.csv")
        plumb.write_csv(u, again)
        self.assertEqual([(b.name, b.acc.tolist(), b.gyr.tolist()) for b in plumb.open(again, imus="all").other_imus],
                         [(b.name, b.acc.tolist(), b.gyr.tolist()) for b in s.other_imus])
        # A session without other IMUs has an empty list, pickled or not.
        m, _ = mikoff()
        self.assertEqual(m.other_imus, [])
        self.assertEqual(pickle.loads(pickle.dumps(m)).other_imus, [])

    def test_result_round_trip(self):
        s, r = mikoff()
        u = pickle.loads(pickle.dumps(r))
        self.assertEqual(u.to_json(), r.to_json())
        self.assertEqual(repr(u), repr(r))
        self.assertEqual(u.parameter_names, r.parameter_names)
        np.testing.assert_array_equal(u.values, r.values)
        np.testing.assert_array_equal(u.sigmas, r.sigmas)
        np.testing.assert_array_equal(u.covariance, r.covariance)
        np.testing.assert_array_equal(u.null_space, r.null_space)
        self.assertEqual({k: vars(v) for k, v in u.parameters.items()},
                         {k: vars(v) for k, v in r.parameters.items()})
        self.assertEqual((u.fit, u.notices, u.warnings, u.sigma_scale),
                         (r.fit, r.notices, r.warnings, r.sigma_scale))
        f1, w1 = r.calibration.apply(s.acc, s.gyr)
        f2, w2 = u.calibration.apply(s.acc, s.gyr)
        np.testing.assert_array_equal(f1, f2)
        np.testing.assert_array_equal(w1, w2)

    def test_gates_and_null_space_round_trip(self):
        sim = plumb.simulate(poses=3, seed=2)
        r = quietly(plumb.calibrate, sim.session, max_iterations=1)
        u = pickle.loads(pickle.dumps(r))
        self.assertEqual(u.fit, r.fit)
        self.assertGreater(len(r.fit["gates"]), 0)
        np.testing.assert_array_equal(u.null_space, r.null_space)
        self.assertEqual(u.null_space_names, r.null_space_names)

    def test_calibration_and_diagnosis_round_trip(self):
        s, r = mikoff()
        c = pickle.loads(pickle.dumps(r.calibration))
        np.testing.assert_array_equal(c.apply(s.acc, s.gyr)[0], r.calibration.apply(s.acc, s.gyr)[0])
        d = quietly(plumb.diagnose, s, confirm=0)
        self.assertEqual(pickle.loads(pickle.dumps(d)).to_json(), d.to_json())


class Stubs(unittest.TestCase):
    PACKAGE = os.path.dirname(plumb.__file__)

    def test_stubs_parse_and_list_every_public_name(self):
        with open(os.path.join(self.PACKAGE, "_plumb.pyi")) as f:
            tree = ast.parse(f.read())
        top, classes = set(), {}
        for node in tree.body:
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                top.add(node.name)
            elif isinstance(node, ast.AnnAssign):
                top.add(node.target.id)
            if isinstance(node, ast.ClassDef):
                classes[node.name] = (
                    {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
                    | {n.target.id for n in node.body if isinstance(n, ast.AnnAssign)})
        module = {n for n in dir(plumb._plumb) if not n.startswith("_")} | {"__version__"}
        self.assertEqual({n for n in top if not n.startswith("_") or n == "__version__"}, module)
        for name, members in classes.items():
            cls = getattr(plumb._plumb, name)
            if issubclass(cls, BaseException):
                continue
            public = {a for a in vars(cls) if not a.startswith("_")}
            self.assertEqual({m for m in members if not m.startswith("_")}, public, name)
        self.assertTrue(os.path.exists(os.path.join(self.PACKAGE, "py.typed")))

    def test_stubtest_when_mypy_is_there(self):
        try:
            import mypy.stubtest  # noqa: F401
        except ImportError:
            self.skipTest("mypy is not installed (not a dependency)")
        import subprocess
        import sys
        run = subprocess.run([sys.executable, "-m", "mypy.stubtest", "plumb._plumb",
                              "--ignore-missing-stub"], capture_output=True, text=True)
        self.assertEqual(run.returncode, 0, run.stdout + run.stderr)


if __name__ == "__main__":
    unittest.main()
