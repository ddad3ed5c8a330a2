#include "plumb/io/text/text_table.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "plumb/io/common/text_scan.h"

namespace plumb::io {
namespace {

using detail::FieldCursor;
using detail::LineSource;

// Value slots of one row: time, accelerometer x y z, gyroscope x y z, temperature.
enum Slot { kTime = 0, kAcc = 1, kGyr = 4, kTemp = 7, kSlots = 8 };
constexpr const char* kSlotLabel[kSlots] = {"time",  "acc x", "acc y", "acc z",
                                            "gyr x", "gyr y", "gyr z", "temperature"};

std::string Where(std::size_t line) { return "line " + std::to_string(line); }

std::string Join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + (n.empty() ? "''" : n);
  return out.empty() ? "(none)" : out;
}

void CheckOptions(const TextTableOptions& o) {
  const auto fail = [](const std::string& what) { throw Error("TextTableOptions: " + what); };
  if (!o.time.given() && !(o.rate_hz > 0.0 && std::isfinite(o.rate_hz))) {
    fail("give a time column or a sample rate rate_hz > 0");
  }
  if (!(o.time_unit_s > 0.0 && std::isfinite(o.time_unit_s))) fail("time_unit_s must be > 0");
  for (const TriadColumns* triad : {&o.acc, &o.gyr}) {
    std::array<bool, 3> seen{};
    for (int i = 0; i < 3; ++i) {
      const int m = std::abs(triad->axis_map[i]);
      if (m < 1 || m > 3 || seen[m - 1]) fail("axis_map must be a signed permutation of 1, 2, 3");
      seen[m - 1] = true;
      if (!(std::isfinite(triad->scale[i]) && triad->scale[i] != 0.0 &&
            std::isfinite(triad->offset[i]))) {
        fail("scale must be finite and non-zero, offset finite");
      }
      if (triad->given() && !triad->axes[i].given()) fail("a triad needs all three columns");
    }
  }
  if (!(std::isfinite(o.temp.scale) && o.temp.scale != 0.0 && std::isfinite(o.temp.offset))) {
    fail("temp.scale must be finite and non-zero, temp.offset finite");
  }
}

// What precedes the data: the header names (row or comment) and the first data row.
struct Preamble {
  std::vector<std::string> names;  ///< column names, empty when the file has none
  std::size_t names_line = 0;      ///< line the names came from
  char delimiter = ' ';
  std::size_t first_row_fields = 0;
};

bool IsComment(std::string_view line, const std::string& prefix) {
  if (prefix.empty()) return false;
  std::size_t i = 0;
  while (i < line.size() && detail::IsBlank(line[i])) ++i;
  return line.compare(i, prefix.size(), prefix) == 0;
}

// Neither blank nor a comment (IsBlankLine and IsComment in one pass over the leading blanks).
bool IsDataRow(std::string_view line, const std::string& prefix) {
  std::size_t i = 0;
  while (i < line.size() && detail::IsBlank(line[i])) ++i;
  if (i == line.size()) return false;
  return prefix.empty() || line.compare(i, prefix.size(), prefix) != 0;
}

// ',' or ';' when the row has one; '\t' for tabs without spaces; else runs of blanks.
char DetectDelimiter(std::string_view row) {
  for (char c : {',', ';'}) {
    if (row.find(c) != std::string_view::npos) return c;
  }
  const std::string_view inner = detail::Trim(row);
  const bool tabs_only =
      inner.find('\t') != std::string_view::npos && inner.find(' ') == std::string_view::npos;
  return tabs_only ? '\t' : ' ';
}

std::size_t CountFields(std::string_view row, char delimiter) {
  FieldCursor cursor(row, delimiter);
  std::string_view field;
  std::size_t n = 0;
  while (cursor.Next(field)) ++n;
  return n;
}

// The resolved layout: which field feeds which slot and how slots become SI outputs.
class TableParser {
 public:
  TableParser(const TextTableOptions& o, const Preamble& pre, const std::string& file)
      : o_(o), pre_(pre), file_(file) {
    Assign(kTime, o.time, true);
    has_acc_ = AssignTriad(kAcc, o.acc);
    has_gyr_ = AssignTriad(kGyr, o.gyr);
    if (!has_acc_ && !has_gyr_) {
      throw InputError(file_, "",
                       "expected accelerometer columns; found columns: " + Join(pre_.names));
    }
    has_temp_ = o.temp.column.given() && Assign(kTemp, o.temp.column, o.temp.required);
    has_time_ = field_of_slot_[kTime] >= 0;
    for (int s = 0; s < kSlots; ++s) {
      if (field_of_slot_[s] >= 0) used_slots_.push_back(s);
    }
    if (has_acc_) Conversion(0, kAcc, o.acc);
    if (has_gyr_) Conversion(3, kGyr, o.gyr);
    source_[6] = kTemp;
    offset_[6] = o.temp.offset;
    factor_[6] = o.temp.scale;
  }

  void Reserve(std::size_t rows) {
    auto& s = session_.series;
    s.t_s.reserve(rows);
    if (has_acc_) s.acc.reserve(rows);
    if (has_gyr_) s.gyr.reserve(rows);
    if (has_temp_) s.temp_c.reserve(rows);
  }

  // Parses one data row. `line_numbers`, if given, receives the line of every kept sample.
  void Row(std::string_view line, std::size_t line_no, std::vector<std::size_t>* line_numbers) {
    double v[kSlots];
    const char* p = line.data();
    const char* const end = p + line.size();
    const std::size_t needed = slot_of_field_.size();
    for (std::size_t i = 0; i < needed; ++i) {
      p = StartOfField(p, end, i, line_no);
      const char* const field = p;
      const int slot = slot_of_field_[i];
      if (slot < 0) {
        p = EndOfField(p, end);
      } else if (!(detail::ScanNumber(p, end, v[slot]) && AtEndOfField(p, end))) {
        NotANumber(line_no, i, {field, Length(field, EndOfField(field, end))});
      }
    }
    const double row_index = static_cast<double>(rows_++);
    for (int s : used_slots_) {
      if (!std::isfinite(v[s])) return NonFinite(line_no, s);
    }
    const double t_s = has_time_ ? v[kTime] * o_.time_unit_s : row_index / o_.rate_hz;
    if (last_line_ > 0 && !(t_s > last_t_s_)) BadTime(line_no, t_s);
    last_t_s_ = t_s;
    last_line_ = line_no;
    ImuSeries& s = session_.series;
    s.t_s.push_back(t_s);
    if (has_acc_) s.acc.emplace_back(Out(v, 0), Out(v, 1), Out(v, 2));
    if (has_gyr_) s.gyr.emplace_back(Out(v, 3), Out(v, 4), Out(v, 5));
    if (has_temp_) s.temp_c.push_back(Out(v, 6));
    if (line_numbers) line_numbers->push_back(line_no);
  }

  Session Finish(const std::string& source) {
    session_.source = source;
    if (skipped_ > 0) {
      session_.warnings.push_back(
          Notice{"nan_rows_skipped",
                 source + ": skipped " + std::to_string(skipped_) +
                     " rows with NaN or infinite values (first at line " +
                     std::to_string(first_skipped_line_) + ")",
                 {}});
    }
    return std::move(session_);
  }

 private:
  static std::size_t Length(const char* begin, const char* end) {
    return static_cast<std::size_t>(end - begin);
  }

  // Field scanning. Padding is spaces and tabs other than the delimiter.
  bool IsPad(char c) const { return c == ' ' || (c == '\t' && pre_.delimiter != '\t'); }

  // The previous field (if any) ended at `p`, on its delimiter or the line's end; returns the
  // start of field `i` (padding skipped) or throws if the row has ended.
  const char* StartOfField(const char* p, const char* end, std::size_t i,
                           std::size_t line_no) const {
    const bool blanks = pre_.delimiter == ' ';
    while (p != end && IsPad(*p)) ++p;
    if (!blanks && i > 0 && p != end) {
      ++p;  // the delimiter
      while (p != end && IsPad(*p)) ++p;
    } else if (p == end && (blanks || i > 0)) {
      throw InputError(file_, Where(line_no),
                       "expected at least " + std::to_string(slot_of_field_.size()) +
                           " columns, found " + std::to_string(i));
    }
    return p;
  }

  // The delimiter (or blank) that ends the field starting at `p`, or the line's end.
  const char* EndOfField(const char* p, const char* end) const {
    if (pre_.delimiter != ' ') {
      const void* found = std::memchr(p, pre_.delimiter, Length(p, end));
      return found ? static_cast<const char*>(found) : end;
    }
    while (p != end && !IsPad(*p)) ++p;
    return p;
  }

  // True when only padding separates `p` from the field's end; leaves `p` there.
  bool AtEndOfField(const char*& p, const char* end) const {
    if (pre_.delimiter == ' ') return p == end || IsPad(*p);
    while (p != end && IsPad(*p)) ++p;
    return p == end || *p == pre_.delimiter;
  }

  // Finds the field of `column`; returns false when it is absent and not required.
  bool Assign(int slot, const Column& column, bool required) {
    if (!column.given()) return false;
    const int field = Resolve(column, required);
    if (field < 0) return false;
    if (static_cast<std::size_t>(field) >= slot_of_field_.size()) {
      slot_of_field_.resize(static_cast<std::size_t>(field) + 1, -1);
    }
    if (slot_of_field_[field] >= 0) {
      throw Error("TextTableOptions: column " + std::to_string(field) + " is used for both " +
                  kSlotLabel[slot_of_field_[field]] + " and " + kSlotLabel[slot]);
    }
    slot_of_field_[field] = slot;
    field_of_slot_[slot] = field;
    return true;
  }

  bool AssignTriad(int first_slot, const TriadColumns& triad) {
    if (!triad.given()) return false;
    int found = 0;
    for (int i = 0; i < 3; ++i) found += Resolve(triad.axes[i], false) >= 0 ? 1 : 0;
    if (found == 0 && !triad.required) return false;
    if (found < 3) {
      for (int i = 0; i < 3; ++i) Resolve(triad.axes[i], true);  // throws for the missing one
    }
    for (int i = 0; i < 3; ++i) Assign(first_slot + i, triad.axes[i], true);
    return true;
  }

  // Field index of `column`, or -1 if absent (an InputError instead when `required`).
  int Resolve(const Column& column, bool required) const {
    if (column.index >= 0) {
      if (static_cast<std::size_t>(column.index) < pre_.first_row_fields || required) {
        return column.index;
      }
      return -1;
    }
    const auto it = std::find(pre_.names.begin(), pre_.names.end(), column.name);
    if (it != pre_.names.end()) return static_cast<int>(it - pre_.names.begin());
    if (!required) return -1;
    if (pre_.names.empty()) {
      throw InputError(file_, "",
                       "column '" + column.name +
                           "' is given by name but the file has no header row or "
                           "comment header naming its columns");
    }
    throw InputError(
        file_, Where(pre_.names_line),
        "expected a column named '" + column.name + "'; found columns: " + Join(pre_.names));
  }

  void Conversion(int first_out, int first_slot, const TriadColumns& triad) {
    for (int i = 0; i < 3; ++i) {
      const int m = triad.axis_map[i];
      const int axis = std::abs(m) - 1;
      source_[first_out + i] = first_slot + axis;
      offset_[first_out + i] = triad.offset[axis];
      factor_[first_out + i] = (m < 0 ? -1.0 : 1.0) * triad.scale[axis];
    }
  }

  float Out(const double* v, int out) const {
    return static_cast<float>((v[source_[out]] - offset_[out]) * factor_[out]);
  }

  std::string ColumnLabel(std::size_t field) const {
    std::string label = "column " + std::to_string(field + 1);
    if (field < pre_.names.size()) label += " '" + pre_.names[field] + "'";
    return label + " (" + kSlotLabel[slot_of_field_[field]] + ")";
  }

  [[noreturn]] void NotANumber(std::size_t line_no, std::size_t field,
                               std::string_view text) const {
    throw InputError(
        file_, Where(line_no),
        ColumnLabel(field) + ": expected a number, found " + detail::Quote(detail::Trim(text)));
  }

  void NonFinite(std::size_t line_no, int slot) {
    if (!o_.allow_nan_rows) {
      throw InputError(file_, Where(line_no),
                       ColumnLabel(static_cast<std::size_t>(field_of_slot_[slot])) +
                           ": NaN or infinite value; expected a finite number (to skip such rows: " +
                           OptionText(Option::kDropNan) + ")",
                       {Option::kDropNan});
    }
    if (skipped_++ == 0) first_skipped_line_ = line_no;
  }

  [[noreturn]] void BadTime(std::size_t line_no, double t_s) const {
    throw InputError(file_, Where(line_no),
                     "time " + detail::FormatNumber(t_s) + " s " +
                         (t_s == last_t_s_ ? "repeats" : "is before") + " the previous row's " +
                         detail::FormatNumber(last_t_s_) + " s (line " +
                         std::to_string(last_line_) + "); expected strictly increasing times");
  }

  const TextTableOptions& o_;
  const Preamble& pre_;
  const std::string& file_;
  std::vector<int> slot_of_field_;  ///< per field up to the last one used: slot or -1
  std::array<int, kSlots> field_of_slot_{-1, -1, -1, -1, -1, -1, -1, -1};
  std::vector<int> used_slots_;
  bool has_time_ = false, has_acc_ = false, has_gyr_ = false, has_temp_ = false;
  // Outputs 0-2 acc, 3-5 gyr (body axes), 6 temperature: (v[source] - offset) * factor.
  std::array<int, 7> source_{};
  std::array<double, 7> offset_{}, factor_{};
  Session session_;
  std::size_t rows_ = 0, skipped_ = 0, first_skipped_line_ = 0, last_line_ = 0;
  double last_t_s_ = 0.0;
};

// Reads the preamble (skipped lines, comments, header) up to and including the first data
// row, which is left in `first_row`. Throws for an empty file or one without data rows.
Preamble ReadPreamble(LineSource& src, const TextTableOptions& o, std::string_view& first_row) {
  std::string_view line;
  bool any_text = false;
  for (std::size_t i = 0; i < o.skip_lines && src.Next(line); ++i) {
    any_text = any_text || !detail::IsBlankLine(line);
  }
  std::string comment, header;
  std::size_t comment_line = 0, header_line = 0;
  bool have_row = false;
  while (src.Next(line)) {
    if (detail::IsBlankLine(line)) continue;
    any_text = true;
    if (IsComment(line, o.comment_prefix)) {
      const std::size_t at = line.find(o.comment_prefix);
      comment.assign(line.substr(at + o.comment_prefix.size()));
      comment_line = src.line_number();
    } else if (o.header_row && header_line == 0) {
      header.assign(line);
      header_line = src.line_number();
    } else {
      have_row = true;
      break;
    }
  }
  if (!any_text) throw InputError(src.name(), "", "empty file; expected a table of samples");
  if (!have_row) {
    throw InputError(
        src.name(), Where(src.line_number()),
        "no data rows" +
            (header_line ? " after the header (line " + std::to_string(header_line) + ")"
                         : std::string()) +
            "; expected rows of numbers");
  }
  Preamble pre;
  first_row = line;
  pre.delimiter = o.delimiter != 0 ? o.delimiter : DetectDelimiter(line);
  pre.first_row_fields = CountFields(line, pre.delimiter);
  if (o.header_row) {
    pre.names = detail::SplitNames(header, pre.delimiter);
    pre.names_line = header_line;
  } else if (comment_line > 0) {
    pre.names = detail::SplitNames(comment, pre.delimiter);
    pre.names_line = comment_line;
  }
  return pre;
}

Session ParseSource(LineSource& src, const TextTableOptions& o,
                    std::vector<std::size_t>* line_numbers = nullptr) {
  CheckOptions(o);
  std::string_view line;
  const Preamble pre = ReadPreamble(src, o, line);
  TableParser parser(o, pre, src.name());
  if (src.size_bytes() > src.offset_bytes()) {
    parser.Reserve((src.size_bytes() - src.offset_bytes()) / (line.size() + 1) + 2);
  }
  parser.Row(line, src.line_number(), line_numbers);
  while (src.Next(line)) {
    if (!IsDataRow(line, o.comment_prefix)) continue;
    parser.Row(line, src.line_number(), line_numbers);
  }
  return parser.Finish(src.name());
}

void CheckAccelerometer(const TextTableOptions& o) {
  if (!o.acc.given()) throw Error("TextTableOptions: the accelerometer columns are not given");
}

// With acc.required false a table may lack the accelerometer, which a Session cannot.
Session CheckHasAccelerometer(Session session) {
  if (session.series.acc.empty()) {
    throw InputError(session.source, "", "expected accelerometer columns; found none");
  }
  return session;
}

}  // namespace

Session ReadTextTable(const std::string& path, const TextTableOptions& options) {
  CheckAccelerometer(options);
  LineSource src = LineSource::FromFile(path);
  return CheckHasAccelerometer(ParseSource(src, options));
}

Session ParseTextTable(std::string_view text, const std::string& name,
                       const TextTableOptions& options) {
  CheckAccelerometer(options);
  LineSource src = LineSource::FromText(text, name);
  return CheckHasAccelerometer(ParseSource(src, options));
}

Session ReadSplitTables(const std::string& acc_path, const std::string& gyr_path,
                        const TextTableOptions& options, const JobRunner& run_jobs) {
  CheckAccelerometer(options);
  if (!options.gyr.given()) {
    throw Error("TextTableOptions: ReadSplitTables needs the gyroscope columns (gyr.axes)");
  }
  TextTableOptions acc_options = options;
  acc_options.gyr = TriadColumns{};
  TextTableOptions gyr_options = options;
  gyr_options.acc = TriadColumns{};
  gyr_options.temp = ScalarColumn{};

  // The two files are read by two jobs (at once through `run_jobs`); the accelerometer
  // file's error, if any, is the one thrown, as when they are read in turn.
  std::vector<std::size_t> acc_lines, gyr_lines;
  Session session, gyr;
  std::exception_ptr errors[2];
  RunJobs(run_jobs, 2, [&](int job) {
    try {
      if (job == 0) {
        LineSource acc_src = LineSource::FromFile(acc_path);
        session = CheckHasAccelerometer(ParseSource(acc_src, acc_options, &acc_lines));
      } else {
        LineSource gyr_src = LineSource::FromFile(gyr_path);
        gyr = ParseSource(gyr_src, gyr_options, &gyr_lines);
      }
    } catch (...) {
      errors[job] = std::current_exception();
    }
  });
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }

  const auto& t_acc = session.series.t_s;
  const auto& t_gyr = gyr.series.t_s;
  constexpr double kTimeTolerance_s = 1e-6;
  const std::size_t common = std::min(t_acc.size(), t_gyr.size());
  for (std::size_t i = 0; i < common; ++i) {
    if (std::abs(t_acc[i] - t_gyr[i]) > kTimeTolerance_s) {
      throw InputError(gyr_path, Where(gyr_lines[i]),
                       "sample " + std::to_string(i) + ": time " + detail::FormatNumber(t_gyr[i]) +
                           " s differs from " + detail::FormatNumber(t_acc[i]) + " s at " +
                           acc_path + " line " + std::to_string(acc_lines[i]) +
                           "; expected the accelerometer and gyroscope files to share their "
                           "timestamps");
    }
  }
  if (t_acc.size() != t_gyr.size()) {
    const bool acc_longer = t_acc.size() > t_gyr.size();
    const std::string& longer = acc_longer ? acc_path : gyr_path;
    const std::size_t extra_line = acc_longer ? acc_lines[common] : gyr_lines[common];
    throw InputError(longer, Where(extra_line),
                     "has " + std::to_string(std::max(t_acc.size(), t_gyr.size())) +
                         " samples, the other file " + (acc_longer ? gyr_path : acc_path) +
                         " has " + std::to_string(common) +
                         "; expected both files to share their timestamps");
  }
  session.series.gyr = std::move(gyr.series.gyr);
  session.source = acc_path + " + " + gyr_path;
  for (auto& w : gyr.warnings) session.warnings.push_back(std::move(w));
  return session;
}

}  // namespace plumb::io
