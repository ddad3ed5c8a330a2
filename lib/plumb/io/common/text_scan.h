// plumb/io/common/text_scan.h — INTERNAL to plumb::io: a chunked line reader, field splitting and
// number parsing shared by the text readers. Not part of the public interface.
//
// Files are read in 1 MiB chunks (the buffer grows only for a longer line), so memory does
// not scale with the file size; lines are returned as views into the buffer, valid until the
// next call. Numbers are parsed without iostreams: an exact fast path for plain decimals,
// std::from_chars for everything else.
#pragma once

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace plumb::io::detail {

/// The whole content of a (small) file; throws plumb::InputError naming it on failure.
std::string ReadWholeFile(const std::string& path);

class LineSource {
 public:
  /// Opens `path`; throws plumb::InputError naming it if it cannot be opened.
  static LineSource FromFile(const std::string& path);
  /// Reads lines from `text` (not copied: it must outlive the source); `name` is used in errors.
  static LineSource FromText(std::string_view text, std::string name);

  /// Next line without its '\n' (and a trailing '\r'); false at the end of the input.
  bool Next(std::string_view& line);
  /// 1-based number of the line last returned by Next.
  std::size_t line_number() const { return line_number_; }
  /// Total input size in bytes (for reserving), 0 if unknown.
  std::size_t size_bytes() const { return size_bytes_; }
  /// Bytes consumed so far.
  std::size_t offset_bytes() const { return consumed_ + pos_; }
  const std::string& name() const { return name_; }

 private:
  friend std::string ReadWholeFile(const std::string& path);
  struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  void Refill();

  std::string name_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  std::vector<char> storage_;  ///< chunk buffer (file mode)
  const char* data_ = nullptr;
  std::size_t pos_ = 0, end_ = 0, consumed_ = 0;
  std::size_t line_number_ = 0, size_bytes_ = 0;
  bool eof_ = false;
};

inline bool IsBlank(char c) { return c == ' ' || c == '\t'; }

/// `s` without leading and trailing spaces and tabs.
inline std::string_view Trim(std::string_view s) {
  while (!s.empty() && IsBlank(s.front())) s.remove_prefix(1);
  while (!s.empty() && IsBlank(s.back())) s.remove_suffix(1);
  return s;
}

/// Splits one line into fields. `delimiter` ' ' means any run of spaces and tabs (leading and
/// trailing ones ignored); any other character separates every field (empty fields kept).
/// Fields are trimmed of surrounding spaces and tabs.
class FieldCursor {
 public:
  FieldCursor(std::string_view line, char delimiter) : line_(line), delimiter_(delimiter) {}
  bool Next(std::string_view& field) {
    const std::size_t n = line_.size();
    if (delimiter_ == ' ') {
      while (pos_ < n && IsBlank(line_[pos_])) ++pos_;
      if (pos_ >= n) return false;
      const std::size_t start = pos_;
      while (pos_ < n && !IsBlank(line_[pos_])) ++pos_;
      field = line_.substr(start, pos_ - start);
      return true;
    }
    if (pos_ > n) return false;
    std::size_t stop = line_.find(delimiter_, pos_);
    if (stop == std::string_view::npos) stop = n;
    field = Trim(line_.substr(pos_, stop - pos_));
    pos_ = stop + 1;
    return true;
  }

 private:
  std::string_view line_;
  char delimiter_;
  std::size_t pos_ = 0;
};

/// Appends the run of digits at `q`, up to 8 of them, to `mantissa` in one step (SWAR) and
/// returns how many it took; 0 (nothing taken) when `q` is not a digit, when fewer than 8
/// bytes remain before `end` or when the digits would pass 19 (the caller's digit loop then
/// goes on). Little-endian only (elsewhere it takes nothing).
inline int TakeDigits(const char*& q, const char* end, std::uint64_t& mantissa, int& digits) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  static constexpr std::uint64_t kPow10[] = {1,      10,      100,      1000,     10000,
                                             100000, 1000000, 10000000, 100000000};
  if (end - q < 8) return 0;
  std::uint64_t chunk;
  std::memcpy(&chunk, q, sizeof chunk);
  // Each byte's value less '0': a digit's is below 10. A byte's high bit in
  // (x + 0x76) | x says it is not a digit; carries only run from a byte that is not one, so
  // the bytes before the first of those read right.
  const std::uint64_t x = chunk ^ 0x3030303030303030u;
  const std::uint64_t not_digit = ((x + 0x7676767676767676u) | x) & 0x8080808080808080u;
  const int k = not_digit == 0 ? 8 : __builtin_ctzll(not_digit) / 8;
  if (k == 0 || digits + k > 19) return 0;
  // The k digits to the top bytes, zeros (leading zeros) below them, then pairs, quads and
  // the eight at once.
  std::uint64_t v = x << (8 * (8 - k));
  v = v * 10 + (v >> 8);
  constexpr std::uint64_t kMask = 0x000000FF000000FFu;
  v = (((v & kMask) * 0x000F424000000064u) + (((v >> 16) & kMask) * 0x0000271000000001u)) >> 32;
  mantissa = mantissa * kPow10[k] + v;
  q += k;
  digits += k;
  return k;
#else
  (void)q, (void)end, (void)mantissa, (void)digits;
  return 0;
#endif
}

/// Exact fast path for plain decimals (Clinger): [-]digits[.digits][(e|E)[+-]digits] with at
/// most 19 digits, a mantissa up to 2^53 and a power of ten within 1e+-22 take one correctly
/// rounded multiplication or division. On success advances `p` past the number; returns false
/// (and leaves `p`) for anything else, which std::from_chars then decides.
[[gnu::always_inline]] inline bool ScanSimpleDecimal(const char*& p, const char* end,
                                                   double& value) {
  static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                      1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const auto is_digit = [](char c) { return static_cast<unsigned>(c - '0') < 10u; };
  const char* q = p;
  const bool negative = q != end && *q == '-';
  if (negative) ++q;
  std::uint64_t mantissa = 0;
  int digits = 0, exponent = 0;
  while (TakeDigits(q, end, mantissa, digits) == 8) continue;
  for (; q != end && is_digit(*q) && digits < 20; ++q, ++digits) {
    mantissa = mantissa * 10 + static_cast<unsigned>(*q - '0');
  }
  if (q != end && *q == '.') {
    const int before_point = digits;
    ++q;
    while (TakeDigits(q, end, mantissa, digits) == 8) continue;
    for (; q != end && is_digit(*q) && digits < 20; ++q, ++digits) {
      mantissa = mantissa * 10 + static_cast<unsigned>(*q - '0');
    }
    exponent = before_point - digits;
  }
  if (digits == 0 || digits > 19 || (q != end && is_digit(*q))) return false;
  if (q != end && (*q == 'e' || *q == 'E')) {
    ++q;
    const bool negative_exponent = q != end && *q == '-';
    if (q != end && (*q == '-' || *q == '+')) ++q;
    if (q == end || !is_digit(*q)) return false;
    int e = 0;
    for (; q != end && is_digit(*q) && e < 1000; ++q) e = e * 10 + (*q - '0');
    exponent += negative_exponent ? -e : e;
  }
  if (mantissa > (std::uint64_t{1} << 53) || exponent < -22 || exponent > 22) return false;
  const double m = static_cast<double>(mantissa);
  value = exponent >= 0 ? m * kPow10[exponent] : m / kPow10[-exponent];
  if (negative) value = -value;
  p = q;
  return true;
}

/// Parses the longest number at `p` (a leading '+' allowed; "nan" and "inf" parse as such)
/// and advances `p` past it; false if there is none.
inline bool ScanNumber(const char*& p, const char* end, double& value) {
  const char* q = (p != end && *p == '+') ? p + 1 : p;
  if (!ScanSimpleDecimal(q, end, value)) {
    const auto result = std::from_chars(q, end, value);
    if (result.ec != std::errc()) return false;
    q = result.ptr;
  }
  p = q;
  return true;
}

/// Parses the whole field as a number.
inline bool ParseNumber(std::string_view field, double& value) {
  const char* p = field.data();
  const char* end = p + field.size();
  return ScanNumber(p, end, value) && p == end;
}

/// Splits `line` into trimmed fields, dropping surrounding double quotes.
std::vector<std::string> SplitNames(std::string_view line, char delimiter);

/// `field` shortened for an error message, in quotes.
std::string Quote(std::string_view field);

/// Shortest text that reads back as the same double.
std::string FormatNumber(double value);

/// True when the line holds only spaces and tabs.
bool IsBlankLine(std::string_view line);

}  // namespace plumb::io::detail
