// The number parser's fast path must agree bit for bit with std::from_chars.
#include "plumb/io/common/text_scan.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>

namespace plumb::io::detail {
namespace {

// Reference: std::from_chars on the whole field (a leading '+' allowed).
bool Reference(const std::string& text, double& value) {
  const char* begin = text.data();
  const char* end = begin + text.size();
  if (begin != end && *begin == '+') ++begin;
  const auto result = std::from_chars(begin, end, value);
  return result.ec == std::errc() && result.ptr == end && begin != end;
}

void ExpectSameAsReference(const std::string& text) {
  double expected = 0.0, got = 0.0;
  const bool ok_expected = Reference(text, expected);
  const bool ok_got = ParseNumber(text, got);
  ASSERT_EQ(ok_got, ok_expected) << "'" << text << "'";
  if (ok_expected && !std::isnan(expected)) {
    ASSERT_EQ(std::memcmp(&got, &expected, sizeof got), 0) << "'" << text << "' " << got;
  }
}

TEST(ParseNumber, AgreesWithFromCharsOnRandomDecimals) {
  std::mt19937_64 rng(1234567);
  std::uniform_real_distribution<double> mantissa(-10.0, 10.0);
  std::uniform_int_distribution<int> exponent(-30, 30), precision(1, 19);
  char text[64];
  for (int i = 0; i < 200000; ++i) {
    const double value = mantissa(rng) * std::pow(10.0, exponent(rng));
    const int digits = precision(rng);
    switch (i % 3) {
      case 0:
        std::snprintf(text, sizeof text, "%.*g", digits, value);
        break;
      case 1:
        std::snprintf(text, sizeof text, "%.*e", digits, value);
        break;
      default:
        std::snprintf(text, sizeof text, "%.*f", digits % 12, value);
        break;
    }
    ExpectSameAsReference(text);
  }
}

// Numbers inside a longer text, as a file's rows give them: the digit runs are then read 8
// bytes at a time (TakeDigits), whatever their length and whatever follows them.
TEST(ScanNumber, AgreesWithFromCharsInsideText) {
  std::mt19937_64 rng(7654321);
  std::uniform_int_distribution<int> digit(0, 9), run(0, 21), exponent(-25, 25), pick(0, 5);
  const char* const after[] = {"", " ", "\t7", ",12345678", "e", "   3.3108000e+04\n"};
  for (int i = 0; i < 100000; ++i) {
    std::string number = (i % 4 == 0) ? "-" : "";
    const int before = run(rng), fraction = run(rng);
    for (int k = 0; k < before; ++k) number += static_cast<char>('0' + digit(rng));
    if (i % 5 != 0) number += '.';
    for (int k = 0; k < fraction; ++k) number += static_cast<char>('0' + digit(rng));
    if (i % 3 == 0) number += "e" + std::to_string(exponent(rng));
    const std::string text = number + after[pick(rng)];
    double expected = 0.0, got = 0.0;
    const auto result = std::from_chars(text.data(), text.data() + text.size(), expected);
    const char* p = text.data();
    const bool ok = ScanNumber(p, text.data() + text.size(), got);
    ASSERT_EQ(ok, result.ec == std::errc()) << "'" << text << "'";
    if (!ok) continue;
    ASSERT_EQ(p, result.ptr) << "'" << text << "'";
    ASSERT_EQ(std::memcmp(&got, &expected, sizeof got), 0) << "'" << text << "' " << got;
  }
}

TEST(ParseNumber, AgreesWithFromCharsOnEdgeCases) {
  for (const char* text : {"0",
                           "-0",
                           "+3",
                           "1.",
                           ".5",
                           "-.5",
                           "1e",
                           "1e+",
                           "1e5x",
                           "1.2.3",
                           "--1",
                           "+-1",
                           "",
                           "-",
                           ".",
                           "e5",
                           "1e400",
                           "1e-400",
                           "0x10",
                           "nan",
                           "-inf",
                           "infinity",
                           "1,5",
                           "12345678901234567890",
                           "1234567890123456789",
                           "0.00000000000000000000000001",
                           "9007199254740993",
                           "9007199254740992",
                           "123456781234567.8",
                           "1.2345678e22",
                           "1.2345678e23",
                           "00000000000000000000001.5",
                           "3.3108000e+04",
                           "1535630275.916451",
                           "10.332114257812501",
                           "12345678",
                           "1234567812345678",
                           " 1",
                           "1 "}) {
    ExpectSameAsReference(text);
  }
}

TEST(ScanNumber, StopsAfterTheNumber) {
  const std::string text = "-9.81234531,0.5";
  const char* p = text.data();
  double value = 0.0;
  ASSERT_TRUE(ScanNumber(p, text.data() + text.size(), value));
  EXPECT_EQ(value, -9.81234531);
  EXPECT_EQ(*p, ',');
}

}  // namespace
}  // namespace plumb::io::detail
