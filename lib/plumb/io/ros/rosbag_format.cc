// plumb/io/ros/rosbag_format.cc — see rosbag_format.h.
#include "plumb/io/ros/rosbag_format.h"

#include <bzlib.h>
#include <libdeflate.h>
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <limits>

#include "plumb/io/common/log_common.h"

namespace plumb::io::detail {
namespace {

/// Calls `field(name, value)` for each "name=value" field of [p, p + n). False, with `why`,
/// when a length runs past the end or a field has no '='.
template <typename Field>
bool ForEachField(const std::uint8_t* p, std::size_t n, std::string* why, Field&& field) {
  std::size_t pos = 0;
  while (pos < n) {
    if (n - pos < 4) {
      *why = "a field length cut by the end of the header (" + std::to_string(n - pos) +
             " bytes left)";
      return false;
    }
    const std::uint32_t len = LoadLittleEndian<std::uint32_t>(p + pos);
    pos += 4;
    if (len > n - pos) {
      *why = "a field of " + std::to_string(len) + " bytes where " + std::to_string(n - pos) +
             " remain";
      return false;
    }
    const auto* begin = reinterpret_cast<const char*>(p + pos);
    // The names are a few letters: a loop beats a call of memchr per field.
    std::size_t name_len = 0;
    while (name_len < len && begin[name_len] != '=') ++name_len;
    if (name_len == len) {
      *why = "a field without '='";
      return false;
    }
    if (!field(std::string_view(begin, name_len),
               std::string_view(begin + name_len + 1, len - name_len - 1))) {
      *why = "field '" + std::string(begin, name_len) + "' of the wrong size (" +
             std::to_string(len - name_len - 1) + " bytes)";
      return false;
    }
    pos += len;
  }
  return true;
}

template <typename T>
bool Load(std::string_view value, T* out) {
  if (value.size() != sizeof(T)) return false;
  *out = LoadLittleEndian<T>(reinterpret_cast<const std::uint8_t*>(value.data()));
  return true;
}

/// Reads a message data record's usual header: its three fields "conn" (4 bytes), "op" (1) and
/// "time" (8), each once, in any order (rosbag writes them in its std::map's order, older
/// recorders in others), 38 bytes in all. Then `out` holds what ForEachField would find; false
/// for any other header (`out` then partly written), which the general walk reads.
bool UsualMessageFields(const std::uint8_t* p, std::size_t n, RosRecordFields* out) {
  constexpr std::size_t kBytes = (4 + 9) + (4 + 4) + (4 + 13);
  if (n != kBytes) return false;
  std::size_t pos = 0;
  for (int k = 0; k < 3; ++k) {
    const std::uint32_t len = LoadLittleEndian<std::uint32_t>(p + pos);
    const std::uint8_t* f = p + pos + 4;
    if (len == 9 && !out->has_conn && std::memcmp(f, "conn=", 5) == 0) {
      out->conn = LoadLittleEndian<std::uint32_t>(f + 5);
      out->has_conn = true;
    } else if (len == 4 && !out->has_op && std::memcmp(f, "op=", 3) == 0) {
      out->op = f[3];
      out->has_op = true;
    } else if (len == 13 && !out->has_time && std::memcmp(f, "time=", 5) == 0) {
      const auto t = LoadLittleEndian<std::uint64_t>(f + 5);
      out->sec = static_cast<std::uint32_t>(t & 0xffffffffu);
      out->nsec = static_cast<std::uint32_t>(t >> 32);
      out->has_time = true;
    } else {
      return false;
    }
    pos += 4 + len;
  }
  return true;  // each of the three once: 38 bytes exactly
}

}  // namespace

bool ParseRecordFields(const std::uint8_t* p, std::size_t n, RosRecordFields* out,
                       std::string* why) {
  *out = RosRecordFields{};
  if (UsualMessageFields(p, n, out)) return true;  // most records of a bag are messages
  *out = RosRecordFields{};
  return ForEachField(p, n, why, [out](std::string_view name, std::string_view value) {
    if (name == "op") return out->has_op = Load(value, &out->op);
    if (name == "conn") return out->has_conn = Load(value, &out->conn);
    if (name == "time") {
      std::uint64_t t = 0;
      if (!Load(value, &t)) return false;
      out->sec = static_cast<std::uint32_t>(t & 0xffffffffu);
      out->nsec = static_cast<std::uint32_t>(t >> 32);
      return out->has_time = true;
    }
    if (name == "topic") {
      out->topic = value;
      return out->has_topic = true;
    }
    if (name == "compression") {
      out->compression = value;
      return true;
    }
    if (name == "size") return out->has_size = Load(value, &out->size);
    if (name == "index_pos") return Load(value, &out->index_pos);
    return true;
  });
}

bool ParseConnectionData(const std::uint8_t* p, std::size_t n, RosConnection* c,
                         std::string* why) {
  return ForEachField(p, n, why, [c](std::string_view name, std::string_view value) {
    if (name == "type") c->type = std::string(value);
    if (name == "md5sum") c->md5sum = std::string(value);
    if (name == "callerid") c->callerid = std::string(value);
    if (name == "latching") c->latching = value == "1";
    return true;
  });
}

namespace {

/// Room for more output: doubles `out` up to `cap` bytes (a chunk's size and one byte, to see
/// data longer than stated). False when it is there already.
bool Grow(std::vector<std::uint8_t>* out, std::size_t used, std::size_t cap) {
  if (used >= cap) return false;
  const std::size_t want = std::min<std::size_t>(cap, std::max<std::size_t>(used * 2, 1 << 16));
  if (want > out->size()) out->resize(want);
  return true;
}

/// At least `bytes` in `out`: a buffer reused chunk after chunk only grows (never shrunk, so
/// never zero-filled again).
void Reserve(std::vector<std::uint8_t>* out, std::size_t bytes) {
  if (out->size() < bytes) out->resize(bytes);
}

bool Bz2(const std::uint8_t* in, std::size_t n, std::uint32_t declared, bool cut,
         std::vector<std::uint8_t>* out, std::size_t* out_size, std::string* why) {
  bz_stream s{};
  if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK) {
    *why = "bz2 could not start";
    return false;
  }
  std::size_t used = 0;
  std::size_t fed = 0;
  int rc = BZ_OK;
  Reserve(out, std::min<std::size_t>(std::size_t{declared} + 1, std::max<std::size_t>(n * 4, 1 << 16)));
  while (true) {
    const std::size_t give = std::min<std::size_t>(n - fed, std::numeric_limits<unsigned>::max());
    s.next_in = const_cast<char*>(reinterpret_cast<const char*>(in + fed));
    s.avail_in = static_cast<unsigned>(give);
    s.next_out = reinterpret_cast<char*>(out->data() + used);
    const std::size_t room = std::min<std::size_t>(out->size(), std::size_t{declared} + 1);
    s.avail_out = static_cast<unsigned>(std::min<std::size_t>(room - used,
                                                              std::numeric_limits<unsigned>::max()));
    const unsigned out_before = s.avail_out;
    rc = BZ2_bzDecompress(&s);
    fed += give - s.avail_in;
    used += out_before - s.avail_out;
    if (rc == BZ_STREAM_END || rc != BZ_OK) break;
    if (s.avail_out == 0) {
      if (!Grow(out, used, std::size_t{declared} + 1)) {
        rc = BZ_DATA_ERROR_MAGIC;  // more than declared
        *why = "bz2 data longer than the chunk's size " + std::to_string(declared);
        break;
      }
      continue;
    }
    if (fed == n) break;  // input ended before the stream did
  }
  BZ2_bzDecompressEnd(&s);
  *out_size = used;
  if (rc == BZ_STREAM_END) {
    if (used == declared) return true;
    *why = "bz2 data of " + std::to_string(used) + " bytes, not the chunk's size " +
           std::to_string(declared);
    return false;
  }
  if (why->empty()) {
    *why = rc == BZ_OK ? (cut ? "bz2 data cut by the end of the file after " + std::to_string(used) +
                                    " bytes"
                              : "bz2 data ended before its stream did")
                       : "bz2 data corrupt (error " + std::to_string(rc) + ") after " +
                             std::to_string(used) + " bytes";
  }
  return false;
}

/// The largest block of the LZ4 frame starting at [in, in + n) as its header states it (the BD
/// byte: 64 KiB to 4 MiB), or 0 when the bytes do not start an LZ4 frame.
std::size_t Lz4BlockMax(const std::uint8_t* in, std::size_t n) {
  if (n < 6 || LoadLittleEndian<std::uint32_t>(in) != 0x184D2204u) return 0;
  const unsigned id = (in[5] >> 4) & 7u;
  return id < 4 ? 0 : std::size_t{1} << (16 + 2 * (id - 4));
}

/// liblz4 decodes a block straight into the output only when the output has room for the
/// frame's largest block; else into its own buffer, copied out after (LZ4F_decompress).
/// @mcap/core states 4 MiB blocks, larger than its chunks: with room for `declared` bytes and
/// one, every chunk was decoded then copied, and that memcpy's time varied from one process to
/// the next, more than half of an MCAP lz4 read in some (docs/performance.md). So when the
/// frame's block is larger than that room, the whole frame is first decoded in one call into a
/// buffer of the block's size (at most 4 MiB, kept from chunk to chunk); a frame that does not
/// then give exactly `declared` bytes (damaged, cut, of another size) is decoded again by Lz4's
/// loop, which says what is wrong and keeps what came out before the fault, as ever.
bool Lz4Whole(LZ4F_dctx* ctx, const std::uint8_t* in, std::size_t n, std::uint32_t declared,
              std::vector<std::uint8_t>* out) {
  const std::size_t block = Lz4BlockMax(in, n);
  if (block <= std::size_t{declared} + 1) return false;
  Reserve(out, block);
  LZ4F_resetDecompressionContext(ctx);
  std::size_t out_size = out->size();
  std::size_t in_size = n;
  const std::size_t hint = LZ4F_decompress(ctx, out->data(), &out_size, in, &in_size, nullptr);
  return !LZ4F_isError(hint) && hint == 0 && out_size == declared;
}

bool Lz4(const std::uint8_t* in, std::size_t n, std::uint32_t declared, bool cut,
         ChunkBuffers* buffers, std::size_t* out_size, std::string* why) {
  if (buffers->lz4 == nullptr &&
      LZ4F_isError(LZ4F_createDecompressionContext(&buffers->lz4, LZ4F_VERSION))) {
    buffers->lz4 = nullptr;
    *why = "lz4 could not start";
    return false;
  }
  LZ4F_dctx* ctx = buffers->lz4;
  std::vector<std::uint8_t>* out = &buffers->out;
  if (!cut && Lz4Whole(ctx, in, n, declared, out)) {
    *out_size = declared;
    return true;
  }
  LZ4F_resetDecompressionContext(ctx);  // a frame left part way by the last chunk
  std::size_t used = 0;
  std::size_t fed = 0;
  std::size_t hint = 1;
  bool ok = true;
  Reserve(out, std::min<std::size_t>(std::size_t{declared} + 1, std::max<std::size_t>(n * 4, 1 << 16)));
  while (hint != 0) {
    const std::size_t room = std::min<std::size_t>(out->size(), std::size_t{declared} + 1);
    if (used == room && !Grow(out, used, std::size_t{declared} + 1)) {
      *why = "lz4 data longer than the chunk's size " + std::to_string(declared);
      ok = false;
      break;
    }
    std::size_t out_size =
        std::min<std::size_t>(out->size(), std::size_t{declared} + 1) - used;
    std::size_t in_size = n - fed;
    hint = LZ4F_decompress(ctx, out->data() + used, &out_size, in + fed, &in_size, nullptr);
    if (LZ4F_isError(hint)) {
      *why = std::string("lz4 data corrupt (") + LZ4F_getErrorName(hint) + ") after " +
             std::to_string(used) + " bytes";
      ok = false;
      break;
    }
    fed += in_size;
    used += out_size;
    if (hint != 0 && fed == n && out_size == 0) {
      *why = cut ? "lz4 data cut by the end of the file after " + std::to_string(used) + " bytes"
                 : "lz4 data ended before its frame did";
      ok = false;
      break;
    }
  }
  *out_size = used;
  if (ok && used != declared) {
    *why = "lz4 data of " + std::to_string(used) + " bytes, not the chunk's size " +
           std::to_string(declared);
    ok = false;
  }
  return ok;
}

/// Once the buffer holds the chunk's size (from the second chunk on), libzstd decodes the frame
/// straight into it in one pass (its content size known); else through its window.
bool Zstd(const std::uint8_t* in, std::size_t n, std::uint32_t declared, bool cut,
          ChunkBuffers* buffers, std::size_t* out_size, std::string* why) {
  if (buffers->zstd == nullptr) buffers->zstd = ZSTD_createDCtx();
  ZSTD_DCtx* ctx = buffers->zstd;
  if (ctx == nullptr) {
    *why = "zstd could not start";
    return false;
  }
  ZSTD_DCtx_reset(ctx, ZSTD_reset_session_only);  // a frame left part way by the last chunk
  std::vector<std::uint8_t>* out = &buffers->out;
  std::size_t used = 0;
  bool ok = true;
  ZSTD_inBuffer src{in, n, 0};
  std::size_t hint = 1;
  Reserve(out, std::min<std::size_t>(std::size_t{declared} + 1, std::max<std::size_t>(n * 4, 1 << 16)));
  while (hint != 0) {
    const std::size_t room = std::min<std::size_t>(out->size(), std::size_t{declared} + 1);
    if (used == room && !Grow(out, used, std::size_t{declared} + 1)) {
      *why = "zstd data longer than the chunk's size " + std::to_string(declared);
      ok = false;
      break;
    }
    ZSTD_outBuffer dst{out->data(), std::min<std::size_t>(out->size(), std::size_t{declared} + 1), used};
    const std::size_t in_before = src.pos;
    hint = ZSTD_decompressStream(ctx, &dst, &src);
    const bool progress = dst.pos != used || src.pos != in_before;
    used = dst.pos;
    if (ZSTD_isError(hint)) {
      *why = std::string("zstd data corrupt (") + ZSTD_getErrorName(hint) + ") after " +
             std::to_string(used) + " bytes";
      ok = false;
      break;
    }
    if (hint != 0 && src.pos == n && !progress) {
      *why = cut ? "zstd data cut by the end of the file after " + std::to_string(used) + " bytes"
                 : "zstd data ended before its frame did";
      ok = false;
      break;
    }
  }
  *out_size = used;
  if (ok && used != declared) {
    *why = "zstd data of " + std::to_string(used) + " bytes, not the chunk's size " +
           std::to_string(declared);
    ok = false;
  }
  return ok;
}

}  // namespace

ChunkBuffers::~ChunkBuffers() {
  ZSTD_freeDCtx(zstd);
  if (lz4 != nullptr) LZ4F_freeDecompressionContext(lz4);
}

std::uint32_t Crc32(const std::uint8_t* p, std::size_t n) {
  return libdeflate_crc32(0, p, n);
}

ChunkBody OpenChunk(std::string_view compression, const std::uint8_t* in, std::size_t n,
                    std::uint32_t declared, bool cut, ChunkBuffers* buffers) {
  ChunkBody body{in, n, true, {}};
  if (compression != "none" && !compression.empty()) {
    body.whole =
        DecompressChunk(compression, in, n, declared, cut, buffers, &body.size, &body.why);
    body.data = buffers->out.data();
  } else if (n != declared) {
    body.whole = false;
    body.why = cut ? "chunk cut by the end of the file after " + std::to_string(n) + " of its " +
                         std::to_string(declared) + " bytes"
                   : "uncompressed chunk of " + std::to_string(n) + " bytes, not its size " +
                         std::to_string(declared);
    body.size = std::min<std::size_t>(n, declared);
  }
  return body;
}

bool DecompressChunk(std::string_view compression, const std::uint8_t* in, std::size_t n,
                     std::uint32_t declared, bool cut, ChunkBuffers* buffers,
                     std::size_t* out_size, std::string* why) {
  std::vector<std::uint8_t>* out = &buffers->out;
  why->clear();
  *out_size = 0;
  if (compression == "none") {
    const std::size_t take = std::min<std::size_t>(n, declared);
    Reserve(out, take);
    std::copy(in, in + take, out->begin());
    *out_size = take;
    if (n == declared) return true;
    *why = cut ? "chunk cut by the end of the file after " + std::to_string(n) + " of its " +
                     std::to_string(declared) + " bytes"
               : "uncompressed chunk of " + std::to_string(n) + " bytes, not its size " +
                     std::to_string(declared);
    return false;
  }
  if (compression == "bz2") return Bz2(in, n, declared, cut, out, out_size, why);
  if (compression == "lz4") return Lz4(in, n, declared, cut, buffers, out_size, why);
  if (compression == "zstd") return Zstd(in, n, declared, cut, buffers, out_size, why);
  *why = "unknown compression '" + std::string(compression.substr(0, 32)) + "'";
  return false;
}

}  // namespace plumb::io::detail
