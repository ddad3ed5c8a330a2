# The Python module `plumb` (python/): pybind11 from Debian (pybind11-dev) against the Python 3
# that has numpy (python3-numpy). PLUMB_BUILD_PYTHON is ON by default when both are found
# (scripts/setup installs them); OFF builds without it.
# Debian's python3 is the one setup gives numpy (a python3 earlier on PATH, e.g. pyenv's, may
# lack it); -DPython3_EXECUTABLE=... chooses another.
if(NOT Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3)
endif()
find_package(Python3 3.8 COMPONENTS Interpreter Development.Module NumPy QUIET)
if(Python3_FOUND)
  find_package(pybind11 2.6 CONFIG QUIET)
endif()
if(Python3_FOUND AND pybind11_FOUND)
  set(_plumb_python_default ON)
else()
  set(_plumb_python_default OFF)
endif()
option(PLUMB_BUILD_PYTHON "Build the Python module plumb (pybind11, numpy)" ${_plumb_python_default})
if(PLUMB_BUILD_PYTHON)
  find_package(Python3 3.8 REQUIRED COMPONENTS Interpreter Development.Module NumPy)
  find_package(pybind11 2.6 CONFIG REQUIRED)
  # Where `cmake --install` puts the package plumb/, relative to the prefix, asked of the
  # interpreter: its 'posix_local' scheme on Debian (/usr/local/lib/python3.X/dist-packages,
  # which Debian's python3 searches; relative, lib/python3.X/dist-packages), else its
  # 'posix_prefix' (lib/python3.X/site-packages). -DPLUMB_PYTHON_INSTALL_DIR=... chooses another
  # (tests/python/test_install.py checks it is on python3's sys.path for PREFIX=/usr/local).
  execute_process(
    COMMAND ${Python3_EXECUTABLE} -c [=[
import os, sysconfig
scheme = "posix_local" if "posix_local" in sysconfig.get_scheme_names() else "posix_prefix"
path = os.path.relpath(sysconfig.get_path("platlib", scheme, vars={"base": "/P", "platbase": "/P"}), "/P")
print(path[len("local/"):] if path.startswith("local/") else path, end="")
]=]
    OUTPUT_VARIABLE _plumb_python_dir RESULT_VARIABLE _plumb_python_rc)
  if(NOT _plumb_python_rc EQUAL 0 OR _plumb_python_dir STREQUAL "")
    set(_plumb_python_dir "lib/python3/dist-packages")
  endif()
  # A build folder configured before kept the old default, which Debian's python3 does not search.
  if(PLUMB_PYTHON_INSTALL_DIR STREQUAL "lib/python3/dist-packages")
    unset(PLUMB_PYTHON_INSTALL_DIR CACHE)
  endif()
  set(PLUMB_PYTHON_INSTALL_DIR "${_plumb_python_dir}" CACHE STRING
      "Install folder of the Python package plumb, relative to CMAKE_INSTALL_PREFIX")
endif()
