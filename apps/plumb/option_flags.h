// apps/plumb/option_flags.h — the library's options (core/option_name.h) as the command line
// spells them: main installs SpellFlag, so the library's messages say "--acc-unit g".
#pragma once

#include <string>
#include <string_view>

#include "plumb/core/option_name.h"

namespace plumb::cli {

/// `option`'s flag, with `value` after a space when given: "--max-iterations", "--acc-unit g".
std::string SpellFlag(Option option, std::string_view value);

}  // namespace plumb::cli
