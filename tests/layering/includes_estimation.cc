// Compiled by tests/layering: against plumb::estimation it compiles; against a module below
// estimation (plumb::signal) the include below must not be found.
#include "plumb/estimation/calibrator.h"

int LayeringProbe() { return static_cast<int>(sizeof(plumb::estimation::CalibrationOptions)); }
