// plumb/io/ros/mcap_fields.h — an MCAP record's opcodes (the ones the reader acts on) and its
// fields, read with every length checked (mcap.h has the format). Internal to the MCAP reader.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "plumb/io/common/log_common.h"

namespace plumb::io::detail {

/// The record opcodes the reader acts on (the others are read past).
namespace mcap_op {
enum McapOp : std::uint8_t {
  kOpHeader = 0x01,
  kOpFooter = 0x02,
  kOpSchema = 0x03,
  kOpChannel = 0x04,
  kOpMessage = 0x05,
  kOpChunk = 0x06,
  kOpChunkIndex = 0x08,
};
}  // namespace mcap_op

/// Reads a record's fields from [p, p + n), every length checked; ok() false once one ran past.
class McapFields {
 public:
  McapFields(const std::uint8_t* p, std::size_t n) : p_(p), n_(n) {}
  bool ok() const { return ok_; }
  std::size_t pos() const { return pos_; }
  template <typename T>
  T Get() {
    if (!ok_ || n_ - pos_ < sizeof(T)) {
      ok_ = false;
      return T{};
    }
    const T v = LoadLittleEndian<T>(p_ + pos_);
    pos_ += sizeof(T);
    return v;
  }
  /// `count` bytes (as far as they go when `partial`: a cut chunk's records).
  std::string_view Bytes(std::uint64_t count, bool partial = false) {
    if (!ok_) return {};
    if (count > n_ - pos_) {
      if (!partial) {
        ok_ = false;
        return {};
      }
      count = n_ - pos_;
    }
    const std::string_view v(reinterpret_cast<const char*>(p_ + pos_), count);
    pos_ += count;
    return v;
  }
  std::string_view String() { return Bytes(Get<std::uint32_t>()); }

 private:
  const std::uint8_t* p_;
  std::size_t n_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

}  // namespace plumb::io::detail
