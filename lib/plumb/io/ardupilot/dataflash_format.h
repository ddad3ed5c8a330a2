// plumb/io/ardupilot/dataflash_format.h — INTERNAL to plumb::io_ardupilot: the DataFlash format
// as both readers (binary .bin, dataflash.cc; text .log, dataflash_text.cc) and the IMU streams
// (dataflash_imu.cc) share it: the record header, the layout of FMT itself, the ONE table of
// format characters (size, storage, scale), building a type from an FMT, and the naming of
// per-instance messages. Not part of the public interface.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/common/log_common.h"

namespace plumb::io::detail {

/// Every binary record starts with these two bytes, then the message-type byte.
constexpr std::uint8_t kDataflashHead1 = 0xA3;
constexpr std::uint8_t kDataflashHead2 = 0x95;
constexpr std::size_t kDataflashHeaderSize = 3;   ///< 0xA3 0x95 <type>

/// FMT, the message that defines every type (itself included): type 128, 89 bytes with the
/// header, format "BBnNZ", columns Type, Length, Name, Format, Columns. Byte offsets and sizes
/// of its fields in the body (after the header):
constexpr std::uint8_t kDataflashFmtType = 128;
constexpr std::size_t kDataflashFmtLength = 89;
constexpr const char* kDataflashFmtFormat = "BBnNZ";
constexpr const char* kDataflashFmtColumns = "Type,Length,Name,Format,Columns";
constexpr std::size_t kFmtTypeOffset = 0;      ///< B: the type defined, 0..255
constexpr std::size_t kFmtLengthOffset = 1;    ///< B: its record length, header included
constexpr std::size_t kFmtNameOffset = 2;      ///< n: its name
constexpr std::size_t kFmtNameSize = 4;
constexpr std::size_t kFmtFormatOffset = 6;    ///< N: its format characters
constexpr std::size_t kFmtFormatSize = 16;
constexpr std::size_t kFmtColumnsOffset = 22;  ///< Z: its column names, comma-separated
constexpr std::size_t kFmtColumnsSize = 64;
constexpr std::size_t kFmtBodySize = 86;       ///< kDataflashFmtLength - kDataflashHeaderSize

/// How the bytes of a format character are stored (little endian).
enum class DataflashStorage : std::uint8_t {
  kUnknown, kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kInt64, kUInt64, kFloat, kDouble,
  kText,   ///< char array, NUL-padded
  kArray,  ///< int16[32]
};

/// One format character of the table (ArduPilot's "DataFlash log format", pymavlink
/// DFReader.py FORMAT_TO_STRUCT).
struct DataflashFormatChar {
  char code = 0;
  std::size_t size = 0;  ///< bytes, 1..64; 0 for a character not in the table
  DataflashStorage storage = DataflashStorage::kUnknown;
  /// The value is stored * scale: 0.01 for c/C/e/E, 1e-7 (degrees) for L, else 1.
  double scale = 1.0;
  /// Text logs write the scaled value v; the binary field holds round(v * inverse_scale):
  /// 100 for c/C/e/E, 1e7 for L; 0 for unscaled characters.
  double inverse_scale = 0.0;
  bool flight_mode = false;  ///< 'M': a flight-mode number (text logs may write its name)
};

/// The entry of format character `c`; size 0 and storage kUnknown when it is not a DataFlash
/// format character.
const DataflashFormatChar& DataflashFormat(char c);

/// The numeric value of a field stored as `storage` at `p` (little endian), times `scale` when
/// it is not 1 (the format character's scale, DataflashFormatChar::scale); NaN for text,
/// arrays and unknown storage. THE decoding of a field: DataflashType::Value and the column
/// readers of the IMU streams use it.
inline double DecodeDataflashValue(const std::uint8_t* p, DataflashStorage storage,
                                   double scale) {
  double v = 0.0;
  switch (storage) {
    case DataflashStorage::kInt8: v = LoadLittleEndian<std::int8_t>(p); break;
    case DataflashStorage::kUInt8: v = LoadLittleEndian<std::uint8_t>(p); break;
    case DataflashStorage::kInt16: v = LoadLittleEndian<std::int16_t>(p); break;
    case DataflashStorage::kUInt16: v = LoadLittleEndian<std::uint16_t>(p); break;
    case DataflashStorage::kInt32: v = LoadLittleEndian<std::int32_t>(p); break;
    case DataflashStorage::kUInt32: v = LoadLittleEndian<std::uint32_t>(p); break;
    case DataflashStorage::kInt64:
      v = static_cast<double>(LoadLittleEndian<std::int64_t>(p));
      break;
    case DataflashStorage::kUInt64:
      v = static_cast<double>(LoadLittleEndian<std::uint64_t>(p));
      break;
    case DataflashStorage::kFloat: v = LoadLittleEndian<float>(p); break;
    case DataflashStorage::kDouble: v = LoadLittleEndian<double>(p); break;
    case DataflashStorage::kText: case DataflashStorage::kArray: case DataflashStorage::kUnknown:
      return std::numeric_limits<double>::quiet_NaN();
  }
  return scale == 1.0 ? v : v * scale;
}

/// One numeric column of a type, read straight from record bodies: DataflashType::Value
/// without looking the column and its format character up for every value.
struct DataflashColumnReader {
  std::size_t offset = 0;  ///< byte offset in the body
  DataflashStorage storage = DataflashStorage::kUnknown;
  double scale = 1.0;      ///< the format character's scale

  /// The reader of column `col` (>= 0) of `t`.
  static DataflashColumnReader Of(const DataflashType& t, int col);
  /// The value in the record body `body` (as DataflashType::Value).
  double Read(const std::uint8_t* body) const {
    return DecodeDataflashValue(body + offset, storage, scale);
  }
};

/// Size in bytes of a DataFlash format character, 0 when unknown.
inline std::size_t DataflashFormatSize(char c) { return DataflashFormat(c).size; }

/// Builds a type from FMT fields (id 0..255, length >= 3 bytes including the header); counts
/// field-size/length mismatches and unknown format characters in `w`.
DataflashType MakeDataflashType(std::uint8_t id, std::size_t length, const std::string& name,
                                const std::string& format, const std::string& columns,
                                DataflashWarnings* w);

/// The built-in FMT type (id 128, 89 bytes, "BBnNZ").
DataflashType DataflashFmtType(DataflashWarnings* w);

/// The rule both readers apply to an FMT for (length, name, format) whose type id is already
/// defined as `existing` (nullptr when not): false, counted in `w`, when the length is below
/// the header size (fmt_invalid) or the id is defined (the first definition wins; counted as
/// fmt_conflicts when this one differs); true when the type is new.
bool AcceptFmt(const DataflashType* existing, std::size_t length, const std::string& name,
               const std::string& format, DataflashWarnings* w);

/// After all records are in: column units from FMTU/UNIT/MULT and params from PARM.
void FinishDataflashLog(DataflashLog* log);

/// The message of a per-instance kind and the column of its instance field (-1 if none):
/// `base` with an I column ("IMU", "ACC"); else `base` + (instance + 1) ("ACC1", "ACC2", ...)
/// when `numbered_from_one`; else `base` itself for instance 0 and `base` + (instance + 1)
/// ("IMU2", "IMU3") for the others. nullptr when the log has no such message.
const DataflashType* DataflashInstanceMessage(const DataflashLog& log, const std::string& base,
                                              int instance, bool numbered_from_one,
                                              int* instance_col);

}  // namespace plumb::io::detail
