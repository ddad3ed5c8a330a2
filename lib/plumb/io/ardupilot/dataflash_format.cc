// plumb/io/ardupilot/dataflash_format.cc — see dataflash_format.h.
#include "plumb/io/ardupilot/dataflash_format.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <tuple>
#include <unordered_set>
#include <vector>

namespace plumb::io::detail {
namespace {

using S = DataflashStorage;

/// THE table of DataFlash format characters (the only one: readers, Value() and the text
/// encoder all look characters up here).
constexpr DataflashFormatChar kFormatChars[] = {
    {'b', 1, S::kInt8},
    {'B', 1, S::kUInt8},
    {'M', 1, S::kUInt8, 1.0, 0.0, true},  // flight mode
    {'h', 2, S::kInt16},
    {'H', 2, S::kUInt16},
    {'c', 2, S::kInt16, 0.01, 100.0},     // int16 * 0.01
    {'C', 2, S::kUInt16, 0.01, 100.0},    // uint16 * 0.01
    {'i', 4, S::kInt32},
    {'I', 4, S::kUInt32},
    {'e', 4, S::kInt32, 0.01, 100.0},     // int32 * 0.01
    {'E', 4, S::kUInt32, 0.01, 100.0},    // uint32 * 0.01
    {'L', 4, S::kInt32, 1e-7, 1e7},       // latitude/longitude, int32 * 1e-7 degrees
    {'f', 4, S::kFloat},
    {'d', 8, S::kDouble},
    {'q', 8, S::kInt64},
    {'Q', 8, S::kUInt64},
    {'n', 4, S::kText},
    {'N', 16, S::kText},
    {'Z', 64, S::kText},
    {'a', 64, S::kArray},                 // int16[32]
};

/// kFormatChars indexed by character code; unknown characters are all-zero entries.
constexpr std::array<DataflashFormatChar, 256> kByCode = [] {
  std::array<DataflashFormatChar, 256> t{};
  for (const DataflashFormatChar& f : kFormatChars) t[static_cast<unsigned char>(f.code)] = f;
  return t;
}();

std::vector<std::string> SplitColumns(const std::string& text) {
  std::vector<std::string> out;
  if (text.empty()) return out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    out.push_back(text.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

/// Fills column units and multipliers from FMTU (FmtType, UnitIds, MultIds), UNIT (Id, Label)
/// and MULT (Id, Mult), when the log has them (and the reader kept FMTU's bodies).
void ApplyUnits(DataflashLog* log) {
  const DataflashType* fmtu = log->Find("FMTU");
  if (fmtu == nullptr || !fmtu->bodies_kept) return;
  std::map<char, std::string> units;
  std::map<char, double> mults;
  if (const DataflashType* u = log->Find("UNIT")) {
    const int id = u->ColumnIndex("Id");
    const int label = u->ColumnIndex("Label");
    if (id >= 0 && label >= 0) {
      for (std::size_t r = 0; r < u->rows; ++r) {
        const double key = u->Value(r, id);
        if (key >= -128 && key < 256) {
          units[static_cast<char>(static_cast<int>(key))] = u->Text(r, label);
        }
      }
    }
  }
  if (const DataflashType* m = log->Find("MULT")) {
    const int id = m->ColumnIndex("Id");
    const int mult = m->ColumnIndex("Mult");
    if (id >= 0 && mult >= 0) {
      for (std::size_t r = 0; r < m->rows; ++r) {
        const double key = m->Value(r, id);
        if (key >= -128 && key < 256) {
          mults[static_cast<char>(static_cast<int>(key))] = m->Value(r, mult);
        }
      }
    }
  }
  const int type_col = fmtu->ColumnIndex("FmtType");
  const int unit_col = fmtu->ColumnIndex("UnitIds");
  const int mult_col = fmtu->ColumnIndex("MultIds");
  if (type_col < 0) return;
  std::array<DataflashType*, 256> by_id{};  // the first type of each id (as a search finds)
  for (auto t = log->types.rbegin(); t != log->types.rend(); ++t) by_id[t->id] = &*t;
  // A row applied twice changes nothing and a later row wins where two set a column, so only
  // the last of identical rows is applied, in log order (a log repeats its FMTU rows).
  using Row = std::tuple<std::uint8_t, std::string_view, std::string_view>;  // id, units, mults
  std::vector<std::pair<DataflashType*, Row>> last_rows;
  std::set<Row> seen;
  for (std::size_t r = fmtu->rows; r-- > 0;) {
    const double type_id = fmtu->Value(r, type_col);
    if (!(type_id >= 0 && type_id < 256) || type_id != std::floor(type_id)) continue;
    DataflashType* const it = by_id[static_cast<std::size_t>(type_id)];
    if (it == nullptr) continue;
    const auto text = [&](int col) {
      return col >= 0 ? fmtu->TextView(r, static_cast<std::size_t>(col)) : std::string_view();
    };
    const Row row{it->id, text(unit_col), text(mult_col)};
    if (seen.insert(row).second) last_rows.push_back({it, row});
  }
  for (auto row = last_rows.rbegin(); row != last_rows.rend(); ++row) {
    DataflashType* const it = row->first;
    const std::string_view unit_ids = std::get<1>(row->second);
    const std::string_view mult_ids = std::get<2>(row->second);
    for (std::size_t c = 0; c < it->columns.size(); ++c) {
      if (c < unit_ids.size() && units.count(unit_ids[c])) it->columns[c].unit = units[unit_ids[c]];
      if (c < mult_ids.size() && mults.count(mult_ids[c])) {
        it->columns[c].multiplier = mults[mult_ids[c]];
      }
    }
  }
}

void CollectParams(DataflashLog* log) {
  const DataflashType* parm = log->Find("PARM");
  if (parm == nullptr) return;
  const int name = parm->ColumnIndex("Name");
  const int value = parm->ColumnIndex("Value");
  if (name < 0 || value < 0 || !parm->bodies_kept) return;  // bodies: the filter may leave them out
  // The last value of each name wins: from the last row back, the first one met is kept.
  std::unordered_set<std::string_view> seen;
  for (std::size_t r = parm->rows; r-- > 0;) {
    const std::string_view key = parm->TextView(r, static_cast<std::size_t>(name));
    if (!seen.insert(key).second) continue;
    log->params.emplace(std::string(key), parm->Value(r, value));
  }
}

}  // namespace

const DataflashFormatChar& DataflashFormat(char c) {
  return kByCode[static_cast<unsigned char>(c)];
}

DataflashColumnReader DataflashColumnReader::Of(const DataflashType& t, int col) {
  const DataflashColumn& c = t.columns[static_cast<std::size_t>(col)];
  const DataflashFormatChar& f = DataflashFormat(c.format);
  return {c.offset, f.storage, f.scale};
}

DataflashType MakeDataflashType(std::uint8_t id, std::size_t length, const std::string& name,
                                const std::string& format, const std::string& columns,
                                DataflashWarnings* w) {
  DataflashType t;
  t.id = id;
  t.name = name;
  t.length = length;
  t.format = format;
  t.body_size = length - kDataflashHeaderSize;
  t.bodies = RecordStore(t.body_size);
  const std::vector<std::string> names = SplitColumns(columns);
  std::size_t offset = 0;
  bool known = true;
  for (std::size_t k = 0; k < format.size(); ++k) {
    const std::size_t size = DataflashFormatSize(format[k]);
    if (size == 0) {
      known = false;
      break;
    }
    if (offset + size <= t.body_size) {
      DataflashColumn col;
      col.name = k < names.size() ? names[k] : "col" + std::to_string(k);
      col.format = format[k];
      col.offset = offset;
      col.size = size;
      t.columns.push_back(std::move(col));
    }
    offset += size;
  }
  if (!known) {
    ++w->fmt_unknown_chars;
  } else if (offset != t.body_size) {
    ++w->fmt_length_mismatches;
  }
  return t;
}

DataflashType DataflashFmtType(DataflashWarnings* w) {
  return MakeDataflashType(kDataflashFmtType, kDataflashFmtLength, "FMT", kDataflashFmtFormat,
                           kDataflashFmtColumns, w);
}

bool AcceptFmt(const DataflashType* existing, std::size_t length, const std::string& name,
               const std::string& format, DataflashWarnings* w) {
  if (length < kDataflashHeaderSize) {
    ++w->fmt_invalid;
    return false;
  }
  if (existing != nullptr) {
    if (existing->length != length || existing->name != name || existing->format != format) {
      ++w->fmt_conflicts;
    }
    return false;
  }
  return true;
}

void FinishDataflashLog(DataflashLog* log) {
  ApplyUnits(log);
  CollectParams(log);
}

const DataflashType* DataflashInstanceMessage(const DataflashLog& log, const std::string& base,
                                              int instance, bool numbered_from_one,
                                              int* instance_col) {
  *instance_col = -1;
  if (const DataflashType* t = log.Find(base); t != nullptr && t->ColumnIndex("I") >= 0) {
    *instance_col = t->ColumnIndex("I");
    return t;
  }
  if (numbered_from_one) return log.Find(base + std::to_string(instance + 1));
  if (instance == 0) return log.Find(base);
  return log.Find(base + std::to_string(instance + 1));
}

}  // namespace plumb::io::detail
