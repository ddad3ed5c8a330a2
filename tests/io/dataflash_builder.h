// Building DataFlash logs byte by byte in tests: FMT records and little-endian fields.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace plumb::io::testing {

using Bytes = std::vector<std::uint8_t>;

/// `text` in a fixed-width, NUL-padded field of `width` bytes.
inline void PutFixed(Bytes* out, const std::string& text, std::size_t width) {
  for (std::size_t k = 0; k < width; ++k) {
    out->push_back(k < text.size() ? static_cast<std::uint8_t>(text[k]) : 0);
  }
}

/// An FMT record (type 128) defining message `type`.
inline Bytes FmtRecord(std::uint8_t type, std::uint8_t length, const std::string& name,
                       const std::string& format, const std::string& columns) {
  Bytes r = {0xA3, 0x95, 128, type, length};
  PutFixed(&r, name, 4);
  PutFixed(&r, format, 16);
  PutFixed(&r, columns, 64);
  return r;
}

/// `value` in little-endian (the machine's) byte order.
template <typename T>
void Put(Bytes* out, T value) {
  std::uint8_t raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  out->insert(out->end(), raw, raw + sizeof(T));
}

inline void Append(Bytes* out, const Bytes& more) {
  out->insert(out->end(), more.begin(), more.end());
}

}  // namespace plumb::io::testing
