// plumb/report/version.h — the version of plumb written into every output.
#pragma once

#include <string>

namespace plumb::report {

/// plumb's version, e.g. "0.1.0" (the CMake project version).
std::string Version();

}  // namespace plumb::report
