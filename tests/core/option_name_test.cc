// core/option_name.h: a message names an option by meaning; the front end that installed its
// speller spells it, the library's own name without one.
#include "plumb/core/option_name.h"

#include <gtest/gtest.h>

#include "plumb/core/error.h"

#include <string>
#include <string_view>
#include <vector>

namespace plumb {
namespace {

/// A front end's speller as the command line's (apps/plumb/option_flags.cc) works.
std::string Flag(Option option, std::string_view value) {
  const std::string flag = option == Option::kMaxIterations ? "--max-iterations"
                           : option == Option::kAccUnit     ? "--acc-unit"
                                                            : "--other";
  return flag + (value.empty() ? "" : " " + std::string(value));
}

/// As the Python module's (python/bindings/keywords.cc) works.
std::string Keyword(Option option, std::string_view value) {
  const std::string keyword = option == Option::kMaxIterations ? "max_iterations"
                              : option == Option::kAccUnit     ? "acc_unit"
                                                               : "other";
  return keyword + (value.empty() ? "" : "=\"" + std::string(value) + "\"");
}

/// A message of the library's that points to two options.
std::string Advice() {
  return "give " + OptionText(Option::kAccUnit, "g") + ", or allow more iterations (" +
         OptionText(Option::kMaxIterations) + ")";
}

// Issue 36 item 3: the library spells no flag; the command line and Python each render theirs.
TEST(OptionName, EachFrontEndSpellsTheOptionsOfOneMessage) {
  SetOptionSpeller(nullptr);
  EXPECT_EQ(Advice(), "give InputOptions::acc.unit = g, or allow more iterations "
                      "(CalibrationOptions::max_iterations)");
  SetOptionSpeller(&Flag);
  EXPECT_EQ(Advice(), "give --acc-unit g, or allow more iterations (--max-iterations)");
  SetOptionSpeller(&Keyword);
  EXPECT_EQ(Advice(), "give acc_unit=\"g\", or allow more iterations (max_iterations)");
  SetOptionSpeller(nullptr);
  EXPECT_EQ(OptionText(Option::kMaxIterations), LibraryName(Option::kMaxIterations));
}

// The options a message names travel with the error as data, whatever the front end's spelling.
TEST(OptionName, ErrorsCarryTheOptionsTheirMessageNames) {
  SetOptionSpeller(nullptr);
  EXPECT_TRUE(Error("no option here").options().empty());
  const Error e("give " + OptionText(Option::kAccScale) + ", " + OptionText(Option::kGyrScale),
                {Option::kAccScale, Option::kGyrScale});
  EXPECT_EQ(e.options(), (std::vector<Option>{Option::kAccScale, Option::kGyrScale}));
  try {
    throw InputError("a.csv", "line 2", "NaN (" + OptionText(Option::kDropNan) + ")",
                     {Option::kDropNan});
  } catch (const Error& caught) {  // as a front end catches it
    EXPECT_EQ(caught.options(), std::vector<Option>{Option::kDropNan});
    EXPECT_EQ(std::string(caught.what()), "a.csv:line 2: NaN (InputOptions::drop_nan_rows)");
  }
  EXPECT_EQ(InsufficientDataError("x", {Option::kSite}).options(), std::vector<Option>{Option::kSite});
}

TEST(OptionName, EveryOptionHasALibraryName) {
  for (int k = 0; k <= static_cast<int>(Option::kClock); ++k) {
    const std::string name = LibraryName(static_cast<Option>(k));
    EXPECT_NE(name, "an option") << k;
    EXPECT_EQ(name.find("--"), std::string::npos) << name;
  }
}

}  // namespace
}  // namespace plumb
