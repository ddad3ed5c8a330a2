#include "plumb/io/text/native_csv.h"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/io/common/atomic_file.h"
#include "plumb/io/common/stream_spool.h"
#include "plumb/io/common/text_scan.h"
#include "plumb/io/text/text_table.h"

namespace plumb::io {

TextTableOptions NativeCsvOptions() {
  TextTableOptions o;
  o.delimiter = ',';
  o.header_row = true;
  o.time = "time_s";
  o.acc.axes = {"acc_x", "acc_y", "acc_z"};
  o.gyr.axes = {"gyr_x", "gyr_y", "gyr_z"};
  o.gyr.required = false;
  o.temp.column = "temp_c";
  o.temp.required = false;
  return o;
}

namespace {

void CheckSizes(const std::string& path, const ImuSeries& s) {
  const std::size_t n = s.size();
  if (s.acc.size() != n || (s.has_gyro() && s.gyr.size() != n) ||
      (s.has_temperature() && s.temp_c.size() != n)) {
    throw Error("cannot write " + path + ": inconsistent series (" + std::to_string(n) +
                " times, " + std::to_string(s.acc.size()) + " acc, " +
                std::to_string(s.gyr.size()) + " gyr, " + std::to_string(s.temp_c.size()) +
                " temperatures)");
  }
}

char* Put(char* out, char* end, double t_s) {
  return std::to_chars(out, end, t_s).ptr;  // shortest exact text
}

char* Put(char* out, char* end, float value) {
  return std::to_chars(out, end, value, std::chars_format::general, 9).ptr;
}

template <typename T>
char* PutField(char* out, char* end, T value) {
  *out++ = ',';
  return Put(out, end, value);
}

/// The columns of the board's IMU k (0: IMU 0's own names).
std::string ColumnName(const char* stem, int k, const char* tail) {
  return stem + (k == 0 ? std::string() : std::to_string(k)) + tail;
}

/// The first line that is neither blank nor a '#' comment: the header ("" when none). A stream
/// (a FIFO) is read from the copy a StreamSpool holds, as every reader reads it.
std::string HeaderLine(const std::string& path) {
  std::ifstream in(OpenPath(path));
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // a UTF-8 byte-order mark
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#') return line;
  }
  return "";
}

/// The native layout of the board's IMU k.
TextTableOptions BoardImuOptions(int k) {
  TextTableOptions o = NativeCsvOptions();
  o.acc.axes = {ColumnName("acc", k, "_x"), ColumnName("acc", k, "_y"), ColumnName("acc", k, "_z")};
  o.gyr.axes = {ColumnName("gyr", k, "_x"), ColumnName("gyr", k, "_y"), ColumnName("gyr", k, "_z")};
  o.temp.column = ColumnName("temp", k, "_c");
  return o;
}

/// The header of IMU k's columns (",acc1_x,...").
std::string HeaderOf(const ImuSeries& s, int k) {
  std::string header;
  for (const char* axis : {"_x", "_y", "_z"}) header += "," + ColumnName("acc", k, axis);
  if (s.has_gyro()) {
    for (const char* axis : {"_x", "_y", "_z"}) header += "," + ColumnName("gyr", k, axis);
  }
  if (s.has_temperature()) header += "," + ColumnName("temp", k, "_c");
  return header;
}

/// Row i of `s`'s columns, each after a comma.
char* PutRow(char* out, char* end, const ImuSeries& s, std::size_t i) {
  for (int k = 0; k < 3; ++k) out = PutField(out, end, s.acc[i][k]);
  if (s.has_gyro()) {
    for (int k = 0; k < 3; ++k) out = PutField(out, end, s.gyr[i][k]);
  }
  if (s.has_temperature()) out = PutField(out, end, s.temp_c[i]);
  return out;
}

}  // namespace

Session ReadNativeCsv(const std::string& path) {
  Session session = ReadTextTable(path, NativeCsvOptions());
  const std::vector<std::string> columns = detail::SplitNames(HeaderLine(path), ',');
  auto names = [&columns](const std::string& column) {
    return std::find(columns.begin(), columns.end(), column) != columns.end();
  };
  for (int k = 1; names(ColumnName("acc", k, "_x")); ++k) {
    Session imu = ReadTextTable(path, BoardImuOptions(k));
    session.other_imus.push_back(BoardImu{k, ColumnName("acc", k, "_x.."), std::move(imu.series), {}, {}});
  }
  return session;
}

void WriteNativeCsv(const std::string& path, const Session& session) {
  const ImuSeries& s = session.series;
  CheckSizes(path, s);
  std::string header = "time_s" + HeaderOf(s, 0);
  for (std::size_t i = 0; i < session.other_imus.size(); ++i) {
    const ImuSeries& other = session.other_imus[i].series;
    CheckSizes(path, other);
    if (other.t_s != s.t_s) {
      throw Error("cannot write " + path + ": IMU " + std::to_string(i + 1) +
                  "'s stamps are not IMU 0's, and a native CSV has one time column");
    }
    header += HeaderOf(other, static_cast<int>(i + 1));
  }
  header += '\n';

  AtomicFileWriter file(path);
  file.Write(header);
  constexpr std::size_t kChunk = std::size_t{1} << 20;
  const std::size_t max_row = 32 * (1 + 7 * (1 + session.other_imus.size()));
  std::string buffer(kChunk + max_row, '\0');
  char* const begin = buffer.data();
  char* const end = begin + buffer.size();
  char* out = begin;
  for (std::size_t i = 0; i < s.size(); ++i) {
    out = Put(out, end, s.t_s[i]);
    out = PutRow(out, end, s, i);
    for (const BoardImu& other : session.other_imus) out = PutRow(out, end, other.series, i);
    *out++ = '\n';
    if (static_cast<std::size_t>(out - begin) >= kChunk) {
      file.Write(std::string_view(begin, static_cast<std::size_t>(out - begin)));
      out = begin;
    }
  }
  file.Write(std::string_view(begin, static_cast<std::size_t>(out - begin)));
  file.Commit();
}

}  // namespace plumb::io
