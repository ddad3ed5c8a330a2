#include "plumb/report/version.h"

namespace plumb::report {

std::string Version() { return PLUMB_VERSION_STRING; }

}  // namespace plumb::report
