// core/error.h: messages keep the file and the place, never a library's own tag.
#include "plumb/core/error.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

namespace plumb {
namespace {

/// The message ParseJsonText gives for `text` read as the file "cal.json".
std::string ParseMessage(const std::string& text) {
  try {
    ParseJsonText("cal.json", [&] { return nlohmann::json::parse(text); });
  } catch (const InputError& e) {
    return e.what();
  }
  return "parsed";
}

// Issue 35 item 8: nlohmann's "[json.exception.out_of_range.406] number overflow" reached the
// user blamed on the samples file; its parse errors carried the library's tag.
TEST(Error, JsonErrorsNameTheFileThePlaceAndNoLibraryTag) {
  EXPECT_EQ(ParseMessage("{\"bias\": 1e400}"),
            "cal.json: a number beyond the range of a double ('1e400'): not valid here; fix or "
            "remove that value");
  EXPECT_EQ(ParseMessage("{\n  \"bias\": [1, 2,\n"),
            "cal.json:line 3, column 1: not valid JSON: syntax error while parsing value - "
            "unexpected end of input; expected '[', '{', or a literal");
  EXPECT_EQ(ParseMessage("{\"a\": 1}"), "parsed");
  // Without the parser's layout, the text is kept whole.
  EXPECT_EQ(std::string(JsonTextError("x.json", "something else").what()),
            "x.json: not valid JSON: something else");
}

TEST(Error, NumbersPrintWithSixSignificantDigits) {
  EXPECT_EQ(Number(1e300), "1e+300");
  EXPECT_EQ(Number(0.0199), "0.0199");
  EXPECT_EQ(Number(200), "200");
}

}  // namespace
}  // namespace plumb
