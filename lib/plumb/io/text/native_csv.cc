#include "plumb/io/text/native_csv.h"

#include <charconv>

#include "plumb/core/error.h"
#include "plumb/io/common/atomic_file.h"
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

}  // namespace

Session ReadNativeCsv(const std::string& path) { return ReadTextTable(path, NativeCsvOptions()); }

void WriteNativeCsv(const std::string& path, const Session& session) {
  const ImuSeries& s = session.series;
  CheckSizes(path, s);
  std::string header = "time_s,acc_x,acc_y,acc_z";
  if (s.has_gyro()) header += ",gyr_x,gyr_y,gyr_z";
  if (s.has_temperature()) header += ",temp_c";
  header += '\n';

  AtomicFileWriter file(path);
  file.Write(header);
  constexpr std::size_t kChunk = std::size_t{1} << 20, kMaxRow = 8 * 32;
  std::string buffer(kChunk + kMaxRow, '\0');
  char* const begin = buffer.data();
  char* const end = begin + buffer.size();
  char* out = begin;
  for (std::size_t i = 0; i < s.size(); ++i) {
    out = Put(out, end, s.t_s[i]);
    for (int k = 0; k < 3; ++k) out = PutField(out, end, s.acc[i][k]);
    if (s.has_gyro()) {
      for (int k = 0; k < 3; ++k) out = PutField(out, end, s.gyr[i][k]);
    }
    if (s.has_temperature()) out = PutField(out, end, s.temp_c[i]);
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
