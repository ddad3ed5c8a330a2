#include "plumb/io/text/segments_file.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>

#include "plumb/core/error.h"
#include "plumb/io/common/text_scan.h"

namespace plumb::io {
namespace {

using detail::LineSource;

// One section as written in the file, before it is matched to samples.
struct RawSection {
  std::string label;
  bool in_seconds = true;  ///< start/end are times (s) rather than sample indices
  double start = 0.0;
  double end = 0.0;
  std::string where;  ///< "line 3" or "section 'x_p'" for errors
};

bool IsRotation(const std::string& label) {
  const std::string suffix = "_rot";
  return label.size() >= suffix.size() &&
         label.compare(label.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Sample range [begin, end) of a section; throws when it lies outside the series or is empty.
std::pair<std::size_t, std::size_t> ToRange(const RawSection& raw, const ImuSeries& series,
                                            const std::string& path) {
  const std::size_t n = series.size();
  const auto fail = [&](const std::string& what) { throw InputError(path, raw.where, what); };
  if (!(std::isfinite(raw.start) && std::isfinite(raw.end) && raw.start < raw.end)) {
    fail("expected finite start < end");
  }
  if (!raw.in_seconds) {
    if (raw.start != std::floor(raw.start) || raw.end != std::floor(raw.end) || raw.start < 0 ||
        raw.end > static_cast<double>(n)) {
      fail("expected whole sample indices 0 <= start < end <= " + std::to_string(n) +
           " (the number of samples)");
    }
    return {static_cast<std::size_t>(raw.start), static_cast<std::size_t>(raw.end)};
  }
  const auto& t = series.t_s;
  const double slack_s = series.median_dt_s();
  if (n == 0 || raw.start < t.front() - slack_s || raw.end > t.back() + slack_s) {
    fail("section " + detail::FormatNumber(raw.start) + ".." + detail::FormatNumber(raw.end) +
         " s lies outside the session's time range" +
         (n ? " " + detail::FormatNumber(t.front()) + ".." + detail::FormatNumber(t.back()) + " s"
            : std::string(" (no samples)")));
  }
  const auto begin = std::lower_bound(t.begin(), t.end(), raw.start) - t.begin();
  const auto end = std::upper_bound(t.begin(), t.end(), raw.end) - t.begin();
  if (end <= begin) fail("section holds no sample");
  return {static_cast<std::size_t>(begin), static_cast<std::size_t>(end)};
}

std::vector<RawSection> ParseJson(const std::string& path, std::string_view text) {
  const nlohmann::ordered_json root =
      ParseJsonText(path, [&] { return nlohmann::ordered_json::parse(text.begin(), text.end()); });
  if (!root.is_object()) {
    throw InputError(path, "",
                     "expected a JSON object of sections {\"label\": {\"start\": i, \"end\": j}}");
  }
  std::vector<RawSection> sections;
  for (const auto& [label, value] : root.items()) {
    RawSection raw;
    raw.label = label;
    raw.where = "section '" + label + "'";
    const bool indices = value.is_object() && value.contains("start") && value.contains("end");
    const bool seconds = value.is_object() && value.contains("start_s") && value.contains("end_s");
    const char* start_key = indices ? "start" : "start_s";
    const char* end_key = indices ? "end" : "end_s";
    if (!(indices || seconds) || !value.at(start_key).is_number() ||
        !value.at(end_key).is_number()) {
      throw InputError(path, raw.where,
                       "expected {\"start\": index, \"end\": index} or "
                       "{\"start_s\": seconds, \"end_s\": seconds}");
    }
    raw.in_seconds = !indices;
    raw.start = value.at(start_key).get<double>();
    raw.end = value.at(end_key).get<double>();
    sections.push_back(std::move(raw));
  }
  return sections;
}

// Column layout of a CSV section file.
struct CsvLayout {
  bool in_seconds = true;
  std::size_t start = 0, end = 1;
  int label = 2;  ///< -1: no label column
};

CsvLayout LayoutFromHeader(const std::vector<std::string>& names, const std::string& path,
                           std::size_t line) {
  CsvLayout layout;
  const auto find = [&](const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? -1 : static_cast<int>(it - names.begin());
  };
  int start = find("start_s"), end = find("end_s");
  if (start < 0 || end < 0) {
    start = find("start");
    end = find("end");
    layout.in_seconds = false;
  }
  if (start < 0 || end < 0) {
    std::string found;
    for (const auto& n : names) found += (found.empty() ? "" : ",") + n;
    throw InputError(path, "line " + std::to_string(line),
                     "expected columns start_s,end_s[,label] or start,end[,label]; found " + found);
  }
  layout.start = static_cast<std::size_t>(start);
  layout.end = static_cast<std::size_t>(end);
  layout.label = find("label");
  if (layout.label < 0) layout.label = find("");
  return layout;
}

std::vector<RawSection> ParseCsv(const std::string& path, std::string_view text) {
  LineSource src = LineSource::FromText(text, path);
  std::string_view line;
  std::vector<RawSection> sections;
  std::optional<CsvLayout> layout;
  while (src.Next(line)) {
    const std::string_view trimmed = detail::Trim(line);
    if (trimmed.empty() || trimmed.front() == '#') continue;
    const std::vector<std::string> fields = detail::SplitNames(line, ',');
    const std::string where = "line " + std::to_string(src.line_number());
    double start = 0.0, end = 0.0;
    if (!layout) {
      const bool numeric = fields.size() >= 2 && detail::ParseNumber(fields[0], start) &&
                           detail::ParseNumber(fields[1], end);
      layout = numeric ? CsvLayout{} : LayoutFromHeader(fields, path, src.line_number());
      if (!numeric) continue;
    }
    const std::size_t needed = std::max(layout->start, layout->end) + 1;
    if (fields.size() < needed) {
      throw InputError(path, where,
                       "expected at least " + std::to_string(needed) + " columns, found " +
                           std::to_string(fields.size()));
    }
    RawSection raw;
    raw.where = where;
    raw.in_seconds = layout->in_seconds;
    for (auto [column, value] : {std::pair{layout->start, &raw.start}, {layout->end, &raw.end}}) {
      if (!detail::ParseNumber(fields[column], *value)) {
        throw InputError(path, where,
                         "column " + std::to_string(column + 1) + ": expected a number, found " +
                             detail::Quote(fields[column]));
      }
    }
    if (layout->label >= 0 && static_cast<std::size_t>(layout->label) < fields.size()) {
      raw.label = fields[static_cast<std::size_t>(layout->label)];
    }
    sections.push_back(std::move(raw));
  }
  return sections;
}

}  // namespace

GivenSections ReadGivenSections(const std::string& path, const ImuSeries& series) {
  const std::string text = detail::ReadWholeFile(path);
  const std::size_t first = text.find_first_not_of("\r\n\t ");
  if (first == std::string::npos) {
    throw InputError(path, "", "empty file; expected a CSV or JSON list of sections");
  }
  const std::vector<RawSection> raw =
      text[first] == '{' ? ParseJson(path, text) : ParseCsv(path, text);
  if (raw.empty()) throw InputError(path, "", "no sections; expected at least one");
  GivenSections out;
  std::vector<std::string> where;  // of each still segment, for the overlap message
  for (const RawSection& r : raw) {
    const auto [begin, end] = ToRange(r, series, path);
    if (IsRotation(r.label)) {
      out.motion.push_back(MotionSection{begin, end, r.label});
      continue;
    }
    StillSegment s;
    s.begin = begin;
    s.end = end;
    s.label = r.label.empty() ? "still #" + std::to_string(out.still.size() + 1) : r.label;
    out.still.push_back(std::move(s));
    where.push_back(r.where);
  }
  std::vector<std::size_t> order(out.still.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return out.still[a].begin < out.still[b].begin; });
  for (std::size_t k = 1; k < order.size(); ++k) {
    const StillSegment& prev = out.still[order[k - 1]];
    if (out.still[order[k]].begin < prev.end) {
      throw InputError(path, where[order[k]],
                       "still segment '" + out.still[order[k]].label + "' overlaps '" + prev.label +
                           "' (" + where[order[k - 1]] + "); expected separate still segments");
    }
  }
  std::vector<StillSegment> sorted;
  for (std::size_t i : order) sorted.push_back(std::move(out.still[i]));
  out.still = std::move(sorted);
  std::sort(out.motion.begin(), out.motion.end(),
            [](const MotionSection& a, const MotionSection& b) { return a.begin < b.begin; });
  return out;
}

std::vector<StillSegment> ReadSegments(const std::string& path, const ImuSeries& series) {
  return ReadGivenSections(path, series).still;
}

}  // namespace plumb::io
