#include "plumb/core/error.h"

#include <cstdio>

#include "plumb/core/number_text.h"

namespace plumb {
namespace {

/// The length of the valid UTF-8 sequence that starts text[i] (2-4), or 0.
std::size_t Utf8Sequence(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(i);
  const std::size_t n = lead >= 0xf0 && lead <= 0xf4 ? 4 : lead >= 0xe0 ? 3 : lead >= 0xc2 ? 2 : 0;
  if (n == 0 || lead > 0xf4 || i + n > text.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xc0) != 0x80) return 0;
  }
  return n;
}

}  // namespace

std::string Printable(std::string_view text, std::size_t max_chars) {
  const bool cut = text.size() > max_chars;
  if (cut) text = text.substr(0, max_chars);
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x80) {
      if (const std::size_t n = Utf8Sequence(text, i); n > 0) {
        out.append(text.substr(i, n));
        i += n;
        continue;
      }
    }
    if ((c < 0x20 && c != '\t' && c != '\n') || c == 0x7f || c >= 0x80) {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    } else {
      out += static_cast<char>(c);
    }
    ++i;
  }
  if (cut) out += "...";
  return out;
}

InputError JsonTextError(const std::string& path, std::string_view parser_what) {
  std::string_view what = parser_what;
  if (!what.empty() && what.front() == '[') {  // the library's tag: "[json.exception.x.N] "
    const auto close = what.find("] ");
    if (close != std::string_view::npos) what.remove_prefix(close + 2);
  }
  std::string where;
  if (const auto at = what.find(" at line "); at != std::string_view::npos) {
    const auto colon = what.find(": ", at);
    if (colon != std::string_view::npos) {
      where = std::string(what.substr(at + 4, colon - at - 4));  // "line 3, column 7"
      what.remove_prefix(colon + 2);
    }
  }
  if (what.rfind("number overflow", 0) == 0) {
    const auto quote = what.find('\'');
    return InputError(path, where,
                      "a number beyond the range of a double" +
                          (quote == std::string_view::npos
                               ? std::string()
                               : " (" + std::string(what.substr(quote)) + ")") +
                          ": not valid here; fix or remove that value");
  }
  return InputError(path, where, "not valid JSON: " + std::string(what));
}

std::string Number(double value, int digits) { return SignificantText(value, digits); }

}  // namespace plumb
