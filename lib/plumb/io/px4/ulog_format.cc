// plumb/io/px4/ulog_format.cc — see ulog_format.h.
#include "plumb/io/px4/ulog_format.h"

namespace plumb::io::detail {
namespace {

/// Parses "type name" or "type[n] name"; nullopt when malformed.
std::optional<ULogFormatField> ParseField(std::string_view item) {
  const std::size_t space = item.find(' ');
  if (space == std::string_view::npos || space == 0 || space + 1 >= item.size()) {
    return std::nullopt;
  }
  ULogFormatField f;
  std::string_view type = item.substr(0, space);
  f.name = std::string(item.substr(space + 1));
  const std::size_t bracket = type.find('[');
  if (bracket != std::string_view::npos) {
    if (type.back() != ']' || bracket == 0) return std::nullopt;
    const std::string_view digits = type.substr(bracket + 1, type.size() - bracket - 2);
    if (digits.empty() || digits.size() > 5) return std::nullopt;
    std::size_t n = 0;
    for (char c : digits) {
      if (c < '0' || c > '9') return std::nullopt;
      n = n * 10 + static_cast<std::size_t>(c - '0');
    }
    if (n == 0 || n > 65535) return std::nullopt;
    f.count = n;
    f.is_array = true;
    type = type.substr(0, bracket);
  }
  f.type = std::string(type);
  return f;
}

}  // namespace

std::optional<std::pair<ULogType, std::size_t>> ULogBasicType(std::string_view name) {
  static const std::pair<std::string_view, std::pair<ULogType, std::size_t>> kTable[] = {
      {"int8_t", {ULogType::kInt8, 1}},     {"uint8_t", {ULogType::kUInt8, 1}},
      {"int16_t", {ULogType::kInt16, 2}},   {"uint16_t", {ULogType::kUInt16, 2}},
      {"int32_t", {ULogType::kInt32, 4}},   {"uint32_t", {ULogType::kUInt32, 4}},
      {"int64_t", {ULogType::kInt64, 8}},   {"uint64_t", {ULogType::kUInt64, 8}},
      {"float", {ULogType::kFloat, 4}},     {"double", {ULogType::kDouble, 8}},
      {"bool", {ULogType::kBool, 1}},       {"char", {ULogType::kChar, 1}}};
  for (const auto& [n, t] : kTable) {
    if (n == name) return t;
  }
  return std::nullopt;
}

std::optional<ULogKeyValue> ParseULogKeyValue(const std::uint8_t* p, std::size_t n) {
  if (n < 1) return std::nullopt;
  const std::size_t key_len = p[0];
  if (key_len == 0 || 1 + key_len > n) return std::nullopt;
  const std::string key(reinterpret_cast<const char*>(p + 1), key_len);
  const std::size_t space = key.find(' ');
  if (space == std::string::npos || space == 0 || space + 1 >= key.size()) return std::nullopt;
  ULogKeyValue kv;
  kv.type = key.substr(0, space);
  kv.name = key.substr(space + 1);
  kv.value = p + 1 + key_len;
  kv.value_size = n - 1 - key_len;
  return kv;
}

std::optional<double> ULogParamValue(const ULogKeyValue& kv) {
  if (kv.value_size != 4) return std::nullopt;
  if (kv.type == "int32_t") return LoadLittleEndian<std::int32_t>(kv.value);
  if (kv.type == "float") return LoadLittleEndian<float>(kv.value);
  return std::nullopt;
}

std::string ULogInfoText(const ULogKeyValue& kv) {
  if (kv.type.rfind("char[", 0) == 0) {
    return std::string(reinterpret_cast<const char*>(kv.value), kv.value_size);
  }
  if (const auto basic = ULogBasicType(kv.type); basic && basic->second == kv.value_size) {
    const std::uint8_t* p = kv.value;
    switch (basic->first) {
      case ULogType::kInt8: return std::to_string(LoadLittleEndian<std::int8_t>(p));
      case ULogType::kUInt8: case ULogType::kBool: case ULogType::kChar:
        return std::to_string(LoadLittleEndian<std::uint8_t>(p));
      case ULogType::kInt16: return std::to_string(LoadLittleEndian<std::int16_t>(p));
      case ULogType::kUInt16: return std::to_string(LoadLittleEndian<std::uint16_t>(p));
      case ULogType::kInt32: return std::to_string(LoadLittleEndian<std::int32_t>(p));
      case ULogType::kUInt32: return std::to_string(LoadLittleEndian<std::uint32_t>(p));
      case ULogType::kInt64: return std::to_string(LoadLittleEndian<std::int64_t>(p));
      case ULogType::kUInt64: return std::to_string(LoadLittleEndian<std::uint64_t>(p));
      case ULogType::kFloat: return std::to_string(LoadLittleEndian<float>(p));
      case ULogType::kDouble: return std::to_string(LoadLittleEndian<double>(p));
    }
  }
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  for (std::size_t k = 0; k < kv.value_size; ++k) {
    out += kHex[kv.value[k] >> 4];
    out += kHex[kv.value[k] & 15];
  }
  return out;
}

bool ParseULogFormat(std::string_view text, std::string* name,
                     std::vector<ULogFormatField>* fields) {
  const std::size_t colon = text.find(':');
  if (colon == std::string_view::npos || colon == 0) return false;
  *name = std::string(text.substr(0, colon));
  std::string_view rest = text.substr(colon + 1);
  while (!rest.empty()) {
    const std::size_t semi = rest.find(';');
    const std::string_view item = rest.substr(0, semi);
    if (!item.empty()) {
      auto f = ParseField(item);
      if (!f) return false;
      fields->push_back(std::move(*f));
    }
    if (semi == std::string_view::npos) break;
    rest = rest.substr(semi + 1);
  }
  return !fields->empty();
}

bool ULogFormatResolver::Resolve(ULogTopic* topic) {
  const auto it = formats_.find(topic->name);
  if (it == formats_.end()) return false;
  const std::optional<Layout> full = LayoutOf(topic->name, 0);
  if (!full || full->size == 0 || full->size > kULogMaxDataBody) return false;
  if (full->columns > column_budget_) return false;
  column_budget_ -= full->columns;
  topic->full_size = full->size;
  std::size_t trailing = 0;
  for (auto f = it->second.rbegin(); f != it->second.rend() && ULogIsPadding(f->name); ++f) {
    trailing += LayoutOf(f->type, 1)->size * f->count;
  }
  topic->body_size = full->size - trailing;
  topic->columns.reserve(full->columns);
  std::size_t offset = 0;
  Flatten(it->second, "", &offset, &topic->columns);
  for (std::size_t c = 0; c < topic->columns.size(); ++c) {
    const ULogColumn& col = topic->columns[c];
    const bool time_type = col.type == ULogType::kUInt64 || col.type == ULogType::kUInt32 ||
                           col.type == ULogType::kUInt16 || col.type == ULogType::kUInt8;
    if (col.name == "timestamp" && time_type) {
      topic->timestamp_col = static_cast<int>(c);
      break;
    }
  }
  return true;
}

std::optional<ULogFormatResolver::Layout> ULogFormatResolver::LayoutOf(const std::string& type,
                                                                       int depth) {
  if (const auto basic = ULogBasicType(type)) return Layout{basic->second, 1};
  if (depth > kULogMaxNesting) return std::nullopt;
  if (const auto hit = cache_.find(type); hit != cache_.end()) return hit->second;
  const auto it = formats_.find(type);
  if (it == formats_.end()) return std::nullopt;
  Layout total;
  for (const ULogFormatField& f : it->second) {
    const std::optional<Layout> l = LayoutOf(f.type, depth + 1);
    if (!l || l->size == 0 || l->size > kULogMaxDataBody / f.count) return std::nullopt;
    total.size += l->size * f.count;
    if (!ULogBasicType(f.type)) {
      total.columns += l->columns * f.count;  // Flatten() keeps nested columns
    } else if (!ULogIsPadding(f.name)) {
      total.columns += f.count;
    }
    if (total.size > kULogMaxDataBody) return std::nullopt;
  }
  cache_[type] = total;
  return total;
}

void ULogFormatResolver::Flatten(const std::vector<ULogFormatField>& fields,
                                 const std::string& prefix, std::size_t* offset,
                                 std::vector<ULogColumn>* out) {
  for (const ULogFormatField& f : fields) {
    const auto basic = ULogBasicType(f.type);
    for (std::size_t i = 0; i < f.count; ++i) {
      std::string label = prefix + f.name;
      if (f.is_array) label += "[" + std::to_string(i) + "]";
      if (basic) {
        if (!ULogIsPadding(f.name)) out->push_back({std::move(label), basic->first, *offset});
        *offset += basic->second;
      } else {
        Flatten(formats_.at(f.type), label + ".", offset, out);
      }
    }
  }
}

}  // namespace plumb::io::detail
