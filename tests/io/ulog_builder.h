// Building ULog files byte by byte in tests: a writer of messages, little-endian fields.
#pragma once

#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <string>
#include <vector>

namespace plumb::io::testing {

using Bytes = std::vector<std::uint8_t>;

/// A tiny ULog writer for the tests.
class Writer {
 public:
  explicit Writer(std::uint8_t version = 1) {
    const std::uint8_t head[8] = {'U', 'L', 'o', 'g', 0x01, 0x12, 0x35, version};
    bytes_.insert(bytes_.end(), head, head + 8);
    U64(1000);
  }
  void Message(char type, const Bytes& body) {
    U16(static_cast<std::uint16_t>(body.size()));
    bytes_.push_back(static_cast<std::uint8_t>(type));
    bytes_.insert(bytes_.end(), body.begin(), body.end());
  }
  void Format(const std::string& text) { Message('F', Bytes(text.begin(), text.end())); }
  void KeyValue(char type, const std::string& key, const Bytes& value, int lead = -1) {
    Bytes b;
    if (lead >= 0) b.push_back(static_cast<std::uint8_t>(lead));
    b.push_back(static_cast<std::uint8_t>(key.size()));
    b.insert(b.end(), key.begin(), key.end());
    b.insert(b.end(), value.begin(), value.end());
    Message(type, b);
  }
  void Add(std::uint8_t multi_id, std::uint16_t msg_id, const std::string& name) {
    Bytes b = {multi_id, static_cast<std::uint8_t>(msg_id), static_cast<std::uint8_t>(msg_id >> 8)};
    b.insert(b.end(), name.begin(), name.end());
    Message('A', b);
  }
  void Data(std::uint16_t msg_id, const Bytes& payload) {
    Bytes b = {static_cast<std::uint8_t>(msg_id), static_cast<std::uint8_t>(msg_id >> 8)};
    b.insert(b.end(), payload.begin(), payload.end());
    Message('D', b);
  }
  void U16(std::uint16_t v) { Raw(&v, 2); }
  void U64(std::uint64_t v) { Raw(&v, 8); }
  void Raw(const void* p, std::size_t n) {
    const auto* c = static_cast<const std::uint8_t*>(p);
    bytes_.insert(bytes_.end(), c, c + n);
  }
  Bytes& bytes() { return bytes_; }

 private:
  Bytes bytes_;
};

template <typename T>
Bytes Le(T v) {
  Bytes b(sizeof(T));
  std::memcpy(b.data(), &v, sizeof(T));
  return b;
}

inline Bytes Cat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const Bytes& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

/// The body of a B message (flag bits) with incompat bit 0 set (data appended) and every
/// offset 0; the first offset lies at file byte 16 + 3 + 16 when the message follows the header.
inline Bytes AppendedDataFlagBits() {
  Bytes flags(40, 0);
  flags[8] = 1;
  return flags;
}

}  // namespace plumb::io::testing
