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
  # Where `cmake --install` puts the package plumb/, relative to the prefix: a folder Debian's
  # python3 searches under /usr/local (site.getsitepackages()).
  set(PLUMB_PYTHON_INSTALL_DIR "lib/python3/dist-packages" CACHE STRING
      "Install folder of the Python package plumb, relative to CMAKE_INSTALL_PREFIX")
endif()
