// plumb/io/ardupilot/dataflash_internal.h — INTERNAL to plumb::io: the pieces the binary (.bin) and
// text (.log) DataFlash readers share. Not part of the public interface.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "plumb/io/ardupilot/dataflash.h"

namespace plumb::io::detail {

constexpr std::uint8_t kDataflashFmtType = 128;   ///< message type of FMT
constexpr std::size_t kDataflashHeaderSize = 3;   ///< 0xA3 0x95 <type>
constexpr std::size_t kDataflashFmtLength = 89;   ///< FMT record length, bytes, header included

/// Size in bytes of a DataFlash format character, 0 when unknown.
std::size_t DataflashFormatSize(char c);

/// Builds a type from FMT fields (id 0..255, length >= 3 bytes including the header); counts
/// field-size/length mismatches and unknown format characters in `w`.
DataflashType MakeDataflashType(std::uint8_t id, std::size_t length, const std::string& name,
                                const std::string& format, const std::string& columns,
                                DataflashWarnings* w);

/// The built-in FMT type (id 128, 89 bytes, "BBnNZ").
DataflashType DataflashFmtType(DataflashWarnings* w);

/// After all records are in: column units from FMTU/UNIT/MULT and params from PARM.
void FinishDataflashLog(DataflashLog* log);

}  // namespace plumb::io::detail
