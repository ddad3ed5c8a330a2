"""`cmake --install BUILD --component python --prefix PREFIX` puts the package plumb where the
interpreter looks for it: PREFIX/PLUMB_PYTHON_INSTALL_DIR/plumb (cmake/PlumbPython.cmake asks the
interpreter), a folder on Debian's python3's sys.path for PREFIX=/usr/local, with the stubs and
py.typed beside the extension; and the installed package imports from there."""
import os
import shutil
import subprocess
import sys
import unittest

BUILD = os.environ["PLUMB_BUILD_DIR"]
CMAKE = os.environ.get("PLUMB_CMAKE", "cmake")
DIR = os.environ["PLUMB_PYTHON_INSTALL_DIR"]
OUT = os.environ["PLUMB_TEST_OUT"]


def clean_env():
    """The environment without PYTHONPATH (and without a user site), as a user's shell has."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["PYTHONNOUSERSITE"] = "1"
    return env


class Install(unittest.TestCase):
    def test_the_folder_is_on_sys_path_for_usr_local(self):
        self.assertFalse(os.path.isabs(DIR), DIR)
        run = subprocess.run([sys.executable, "-c", "import sys; print('\\n'.join(sys.path))"],
                             capture_output=True, text=True, env=clean_env(), check=True)
        self.assertIn(os.path.join("/usr/local", DIR), run.stdout.splitlines())

    def test_installed_package_imports(self):
        prefix = os.path.join(OUT, "prefix")
        shutil.rmtree(prefix, ignore_errors=True)
        subprocess.run([CMAKE, "--install", BUILD, "--component", "python", "--prefix", prefix],
                       check=True, capture_output=True)
        package = os.path.join(prefix, DIR, "plumb")
        names = os.listdir(package)
        for name in ["__init__.py", "_plumb.pyi", "py.typed"]:
            self.assertIn(name, names)
        self.assertTrue(any(n.startswith("_plumb") and n.endswith(".so") for n in names), names)
        code = ("import sys; sys.path.insert(0, sys.argv[1]); import plumb; "
                "print(plumb.__file__); print(plumb.Session.from_arrays([0.0, 0.01], "
                "[[0, 0, -9.8], [0, 0, -9.8]]))")
        run = subprocess.run([sys.executable, "-c", code, os.path.join(prefix, DIR)],
                             capture_output=True, text=True, env=clean_env(), cwd=OUT)
        self.assertEqual(run.returncode, 0, run.stderr)
        lines = run.stdout.splitlines()
        self.assertEqual(lines[0], os.path.join(package, "__init__.py"))
        self.assertEqual(lines[1], "<plumb.Session arrays: 2 samples, 0.01 s>")


if __name__ == "__main__":
    unittest.main()
