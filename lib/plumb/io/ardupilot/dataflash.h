// plumb/io/ardupilot/dataflash.h — ArduPilot DataFlash binary logs (.bin), driven by the log's own
// FMT.
//
// Format (ArduPilot "DataFlash log format", pymavlink DFReader.py): every record is the two
// header bytes 0xA3 0x95, a message-type byte, then a little-endian body. FMT (type 128,
// 89 bytes, "BBnNZ": Type, Length, Name, Format, Columns) defines each type; Length counts the
// 3 header bytes. Format characters and sizes: b/B 1 (int8/uint8), h/H 2, i/I 4, f 4 (float),
// d 8 (double), q/Q 8 (int64/uint64), n 4 / N 16 / Z 64 (char arrays), c/C 2 (int16/uint16
// * 0.01), e/E 4 (int32/uint32 * 0.01), L 4 (int32 lat/lon * 1e-7 degrees), M 1 (uint8 flight
// mode), a 64 (int16[32]).
//
// Decoding contract (one pass over the file, read forward in chunks by ReadDataflash):
//  * The first FMT seen for a type wins; a later FMT that differs is ignored and counted.
//  * The FMT length is trusted: fields are decoded while they fit in the body; extra body
//    bytes are ignored; a mismatch between the field sizes and the length is counted
//    (copter 3.4's BAR3 has one).
//  * Bytes that do not start a record of a known type are skipped one by one, i.e. the reader
//    resynchronises on the next 0xA3 0x95 <known type>; skipped bytes are counted.
//  * A record whose header is found but whose body runs past the end of the file (or 1-2
//    trailing bytes that are a prefix of the header) is the truncated last record: dropped and
//    counted.
//  * A type whose FMT has an unknown format character keeps its records (counted, bytes kept)
//    but only the columns before that character are decodable.
//
// Storage ("compact per-type table"): each kept type (RecordFilter) keeps the raw bodies of its
// records (RecordStore: row-major blocks, body_size bytes per record, exactly as in the file),
// and columns are decoded on access with their byte offsets. Memory is about the kept bodies;
// reading is a bounds-checked copy per kept record, with no per-record allocation and no
// counting pass. An IMU message the filter asks to decode (RecordFilter::decode; a session
// reads IMU, IMU2, ... so) keeps no bodies: the binary reader decodes its time, AccX/Y/Z,
// GyrX/Y/Z and T/Temp into per-instance samples as each record goes by, while it is in the
// cache (DataflashType::imu), with ImuFromDataflash's rule for times applied as it goes.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/jobs.h"
#include "plumb/io/common/flight_log.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/common/split_read.h"

namespace plumb::io {

/// One field of a DataFlash message type, as its FMT declared it.
struct DataflashColumn {
  std::string name;         ///< column name from the FMT ("col<k>" when the FMT lists too few)
  char format = 0;          ///< format character (see the file comment)
  std::size_t offset = 0;   ///< byte offset inside the record body (after the 3 header bytes)
  std::size_t size = 0;     ///< field size, bytes, 1..64
  /// Unit label from FMTU + UNIT (e.g. "s", "m/s/s", "rad/s"); empty when the log has none.
  std::string unit;
  /// Multiplier from FMTU + MULT that turns the stored value into `unit` (NOT applied by
  /// Value(); the format-character scales of c/C/e/E/L are applied). 0 when unknown.
  double multiplier = 0.0;
};

/// A record an IMU's rule for times left out: its place among the instance's records (0 for the
/// first) and its time as read, s.
struct DataflashDroppedRecord {
  std::size_t record = 0;
  double t_s = 0.0;
};

/// The samples of one instance of an IMU message, decoded by the binary reader as it met the
/// records (RecordFilter::decode; see DataflashType::imu).
struct DataflashImuDecoded {
  std::size_t records = 0;    ///< records of this instance, kept as samples or not
  double first_time = 0.0;    ///< time column (TimeUS or TimeMS, unscaled) of its first record
  double last_time = 0.0;     ///< the same of its last record
  /// The samples ImuFromDataflash gives for this instance (its rule for times applied), in
  /// the log's units; read by ImuFromDataflash and DataflashImuInstances.
  ImuSeries series;
  /// The reader's state: the last sample of `series` is this instance's last record, kept
  /// only if the next record's time is above its own (else taken out again); false after the
  /// last record.
  bool last_on_trial = false;
  /// The first record the rule left out; nullopt when none was.
  std::optional<DataflashDroppedRecord> first_dropped;
  /// The first it left out after the first DataflashImuDecoder::kHeadRecords records: what a
  /// join of this part after another needs, its first records being replayed there.
  std::optional<DataflashDroppedRecord> first_dropped_after_head;
};

/// All records of one message type.
struct DataflashType {
  std::uint8_t id = 0;          ///< message-type byte, 0..255
  std::string name;             ///< e.g. "IMU", up to 4 characters
  std::size_t length = 0;       ///< record length from the FMT, bytes, including the header
  std::string format;           ///< format string from the FMT
  std::vector<DataflashColumn> columns;  ///< decodable columns, in record order
  std::size_t body_size = 0;    ///< length - 3, bytes per stored record
  std::size_t rows = 0;         ///< number of records decoded
  RecordStore bodies;           ///< the record bodies in order, body_size bytes each
  /// False when the reader's RecordFilter left this type's bodies out (rows still counted):
  /// Value, Text, Array and Column then throw plumb::Error.
  bool bodies_kept = true;
  /// True when the binary reader decoded this IMU message's samples in its pass instead of
  /// keeping its bodies (RecordFilter::decode, for a message with a TimeUS/TimeMS and AccX/Y/Z
  /// column): bodies_kept is then false, and `imu` holds the samples.
  bool imu_decoded = false;
  /// With imu_decoded: the samples by instance, the I value (0..255) of the records of "IMU"
  /// with an I column, else 0 for all records (IMU2 is one instance); records whose I is not
  /// a whole number in 0..255 belong to no instance (ImuFromDataflash never selects them).
  std::vector<DataflashImuDecoded> imu;

  /// Bytes this type holds of the log: its bodies, or with imu_decoded its records counted at
  /// body size (the decoded samples take a little less).
  std::size_t KeptBytes() const { return imu_decoded ? rows * body_size : bodies.size(); }
  /// Index of the column called `column`, or -1.
  int ColumnIndex(std::string_view column) const;
  /// Numeric value of record `row`, column `col`, with the format-character scale applied
  /// (c/C/e/E * 0.01, L * 1e-7). NaN for text and array columns. Precondition: indices valid.
  double Value(std::size_t row, std::size_t col) const;
  /// Text of an n/N/Z column up to its first NUL; empty for other columns.
  std::string Text(std::size_t row, std::size_t col) const;
  /// Text() without a copy: a view of the stored body, valid while this type lives.
  std::string_view TextView(std::size_t row, std::size_t col) const;
  /// The 32 int16 values of an 'a' column; zeros for other columns.
  std::array<std::int16_t, 32> Array(std::size_t row, std::size_t col) const;
  /// Every value of the column called `column` (see Value()). Throws plumb::Error if absent.
  std::vector<double> Column(std::string_view column) const;
};

/// What the reader skipped or repaired. Counts, never fatal.
struct DataflashWarnings {
  std::size_t bytes_skipped = 0;          ///< bytes outside any decoded record
  std::size_t skip_runs = 0;              ///< separate runs of skipped bytes (resyncs)
  std::size_t first_skip_offset = 0;      ///< byte offset of the first skipped byte (if any)
  std::size_t truncated_records = 0;      ///< 0 or 1: the cut last record, dropped
  std::size_t truncated_bytes = 0;        ///< bytes of that dropped record
  std::size_t fmt_length_mismatches = 0;  ///< FMTs whose field sizes != length - 3
  std::size_t fmt_conflicts = 0;          ///< later FMTs differing from the first; ignored
  std::size_t fmt_invalid = 0;            ///< FMTs with length < 3 (ignored)
  std::size_t fmt_unknown_chars = 0;      ///< FMTs with an unknown format character
  // Text logs (.log) only:
  std::size_t text_header_lines = 0;      ///< non-blank lines before the first FMT line, ignored
  std::size_t text_bad_lines = 0;         ///< malformed lines after the first FMT, skipped
  std::size_t text_first_bad_line = 0;    ///< 1-based number of the first one (0: none)
  std::string text_first_bad_what;        ///< what was wrong with it
  std::size_t text_mode_names = 0;        ///< 'M' fields holding a mode name, stored as 255

  bool any() const;
  /// One readable line per non-zero count.
  std::vector<std::string> Describe() const;
};

/// A decoded DataFlash log.
struct DataflashLog {
  std::string source;                ///< file name (or the name given to ParseDataflash)
  std::size_t size_bytes = 0;        ///< input size, bytes
  std::vector<DataflashType> types;  ///< every defined type, in order of definition (FMT first)
  std::map<std::string, double> params;  ///< PARM Name -> Value, last value wins
  DataflashWarnings warnings;

  /// The type called `name`, or nullptr.
  const DataflashType* Find(std::string_view name) const;
  /// (name, record count) of every type with at least one record, in definition order.
  std::vector<std::pair<std::string, std::size_t>> MessageCounts() const;
};

/// How ReadDataflash reads a file: in one part, or in parts at once, two by default
/// (SplitReadOptions). A .bin's later part starts at a record boundary (16 records of known types
/// in a row); it stops at a record header of a type not defined in the lead (ArduPilot writes the
/// FMTs of the types it logs first) or an FMT defining a new type; its IMU samples are joined to
/// the first part's under the rule for times as if read in one pass (DataflashParser::Absorb).
using DataflashReadOptions = SplitReadOptions;

/// Reads and decodes a .bin log. Throws plumb::InputError(path, "byte N", what) when the file
/// cannot be read or holds no FMT record at all.
/// `filter`: the types whose record bodies are kept (RecordFilter; default all).
/// `options`: in one part or two at once (DataflashReadOptions; default one).
DataflashLog ReadDataflash(const std::string& path, const RecordFilter& filter = {},
                           const DataflashReadOptions& options = {});

/// Decodes a log held in memory; `source` names it in errors. Same contract as ReadDataflash.
DataflashLog ParseDataflash(const std::uint8_t* data, std::size_t size,
                            const std::string& source, const RecordFilter& filter = {},
                            const DataflashReadOptions& options = {});

/// Reads and decodes an ArduPilot TEXT log (.log, as Mission Planner writes it) into the same
/// DataflashLog a .bin gives; see ParseDataflashText. Throws plumb::InputError(path, "", what)
/// when the file cannot be read, and as ParseDataflashText.
DataflashLog ReadDataflashText(const std::string& path, const RecordFilter& filter = {});

/// Decodes a text log held in memory; `source` names it in errors.
///
/// Format: one record per line, fields separated by commas (", " or ","), the message name
/// first: `FMT, <type>, <length>, <name>, <format>, <col1>,<col2>,...` defines a type (the
/// column list is the rest of the line; the FMT of FMT may omit "Columns"), `PARM, NAME, 1.5`,
/// `IMU, 95892, 0.00033, ...`. Values are written already scaled (c/C/e/E in units of 0.01
/// of the stored integer, L in degrees), flight modes ('M') may be names, NaN as "NaN".
///
/// Decoding contract (same storage as the binary reader, so DataflashType::Value/Column/Text
/// work unchanged): each row's values are encoded into the binary body layout of its FMT
/// (body = FMT length - 3 bytes, fields that do not fit the length dropped, zero padding):
/// integers must be integral and in the type's range; c/C/e/E are stored as round(v * 100),
/// L as round(v * 1e7); f is the float nearest to the text's double, d the double, NaN kept;
/// n/N/Z text is stored up to the field width; 'a' arrays are stored as zeros; a non-numeric
/// 'M' (a mode name) is stored as 255 and counted. A last text column (n/N/Z) takes the rest
/// of the line, commas included (MSG texts). Lines before the first FMT line are header
/// lines ("ArduCopter V3.1", "Free RAM: ..."), ignored and counted. After it, a line whose
/// name is not a defined type, with a wrong field count or a value that does not parse or fit
/// is skipped and counted with the number of the first one, never fatal. FMT lines follow the
/// binary rules (first definition of a type id or name wins, length < 3 ignored, ...).
/// Throws plumb::InputError(source, "line N", what) when there is no FMT line at all.
DataflashLog ParseDataflashText(const char* data, std::size_t size, const std::string& source,
                                const RecordFilter& filter = {});

/// True when the file looks like a text DataFlash log: no binary header (0xA3 0x95) at the
/// start, only printable text, and a line starting with "FMT," among the first 16 non-blank
/// lines of its first 8 KiB (after a header such as "ArduCopter V3.1" or "Free RAM: 1044").
bool LooksLikeDataflashText(const std::string& path);

/// One IMU instance available in a log.
struct DataflashImuInfo {
  int instance = 0;          ///< 0-based: IMU / I==0 is 0, IMU2 / I==1 is 1, ...
  std::string message;       ///< "IMU" (with an I column) or "IMU", "IMU2", "IMU3"
  std::size_t samples = 0;   ///< records of this instance
  double rate_hz = 0.0;      ///< (samples - 1) / (last time - first time); 0 if undefined
  bool has_temperature = false;  ///< the message has a T or Temp column
};

/// IMU instances present in `log` (from the IMU messages), sorted by instance.
std::vector<DataflashImuInfo> DataflashImuInstances(const DataflashLog& log);

/// The samples of IMU instance `instance` (0-based, see DataflashImuInfo): t_s from TimeUS
/// (* 1e-6) or TimeMS (* 1e-3), acc = AccX/Y/Z m/s^2 and gyr = GyrX/Y/Z rad/s (FRD body frame,
/// already calibrated by ArduPilot), temp_c from T or Temp when present. A sample is dropped
/// when its time is not finite, does not exceed the last kept sample's, or is not below the
/// next record's (a corrupted spike), so one bad time stamp costs one sample. Throws
/// plumb::InputError naming the log when the instance has no samples or the message lacks a
/// time or Acc column.
ImuSeries ImuFromDataflash(const DataflashLog& log, int instance);

/// The samples of IMU instance `instance` as the binary reader decoded them in its pass
/// (RecordFilter::decode; DataflashType::imu), by reference: the samples ImuFromDataflash
/// returns a copy of. nullptr when the reader kept that message's bodies instead (a text log,
/// a filter without decode) or the instance has no records.
const ImuSeries* DecodedDataflashImu(const DataflashLog& log, int instance);

/// The records of IMU instance `instance` in the log, kept as samples or not: more than
/// ImuFromDataflash's samples when its rule for times left some out. 0 when there is no such
/// instance.
std::size_t DataflashImuRecords(const DataflashLog& log, int instance);

/// The time as read (s) of the first record of IMU instance `instance` that ImuFromDataflash's
/// rule for times leaves out; nullopt when it leaves none out (or there is no such instance).
std::optional<double> DataflashImuFirstDropped(const DataflashLog& log, int instance);

/// Every IMU stream of a DataFlash log (binary or text), in this order per instance:
///  * "IMU" (rows with I == k) or "IMU", "IMU2", "IMU3" (k = 0, 1, 2): accelerometer and
///    gyroscope (and temperature from T/Temp) at the logging rate, after ArduPilot's low-pass
///    filters. Listed even with zero rows when the FMT defines it (samples = 0).
///  * "ACC" / "GYR" (rows with I == k; 3.x logs: "ACC1".."ACC3", "GYR1".."GYR3"): every
///    sensor sample before filtering (INS_RAW_LOG_OPT / LOG_BITMASK IMU_RAW), times from
///    SampleUS. Choice made here: when ACC and GYR of an instance have the same number of
///    samples and each i-th pair is less than half a median gyro interval apart, they are also
///    offered paired as one stream "ACC+GYR" (accelerometer times); otherwise only separately:
///    "ACC" accelerometer-only, "GYR" gyroscope-only.
///  * "ISBD_ACC" / "ISBD_GYR": the batch sampler (ISBH header + ISBD data): sensor type 0 =
///    accelerometer, 1 = gyroscope, per ISBH instance; sample j of a batch (j = ISBD seqno * 32
///    + position) at SampleUS * 1e-6 + j / smp_rate s, value = int16 / mul. Accelerometer-only
///    or gyroscope-only; rate_hz is the median ISBH smp_rate (batches are not contiguous).
///    With INS_LOG_BAT_OPT post-filter logging ArduPilot logs filtered samples and may offset
///    the instance by the sensor count; they are listed as logged.
/// ArduPilot computes ACC/GYR/ISBD from the same corrected sample as IMU
/// (AP_InertialSensor_Backend: _rotate_and_correct_accel/_gyro run before the raw-sample
/// notification that logs them), so `applied` is the same INS_* correction for all; the
/// filters are not part of it. `undoable` is true when the log holds every parameter of that
/// correction, AHRS_ORIENTATION is a known rotation and, when INS_TCALn_ENABLE = 1, the
/// stream has a temperature.
std::vector<ImuStreamInfo> DataflashImuStreams(const DataflashLog& log);

/// The samples of the stream `selection` names (stream + imu; an empty stream means the
/// default for `selection.imu`: IMU, else ACC+GYR, else ACC, else ISBD_ACC), inside the time
/// window [from_s, to_s], AS LOGGED (nothing undone; see ArdupilotSession). Accelerometer-only
/// streams give an empty gyr. Gyroscope-only streams (GYR, ISBD_GYR) are listed but cannot
/// be selected: plumb needs accelerometer samples (plumb::InputError says so). Samples whose
/// time does not increase are dropped (see ImuFromDataflash). Throws plumb::InputError naming
/// the log when the stream is absent, gyroscope-only or has no samples in the window.
/// `info` (optional): set to the stream's description (as FindDataflashStream gives it), from
/// the same decoded samples.
ImuSeries DataflashStream(const DataflashLog& log, const FlightLogSelection& selection,
                          ImuStreamInfo* info = nullptr);

/// The stream DataflashStream would read for `selection`, or nullopt.
std::optional<ImuStreamInfo> FindDataflashStream(const DataflashLog& log,
                                                 const FlightLogSelection& selection);

}  // namespace plumb::io
