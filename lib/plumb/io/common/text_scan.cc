#include "plumb/io/common/text_scan.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "plumb/core/error.h"
#include "plumb/io/common/stream_spool.h"

namespace plumb::io::detail {
namespace {
constexpr std::size_t kChunkBytes = std::size_t{1} << 20;
}  // namespace

LineSource LineSource::FromFile(const std::string& path) {
  LineSource source;
  source.name_ = path;
  struct stat info {};
  const std::string open_path = OpenPath(path);
  if (::stat(open_path.c_str(), &info) == 0 && S_ISDIR(info.st_mode)) {
    throw InputError(path, "", "is a folder, expected a file");
  }
  source.file_.reset(std::fopen(open_path.c_str(), "rb"));
  if (!source.file_) {
    throw InputError(path, "", std::string("cannot open: ") + std::strerror(errno));
  }
  source.size_bytes_ = static_cast<std::size_t>(info.st_size);
  source.storage_.resize(kChunkBytes);
  source.data_ = source.storage_.data();
  return source;
}

LineSource LineSource::FromText(std::string_view text, std::string name) {
  LineSource source;
  source.name_ = std::move(name);
  source.data_ = text.data();
  source.end_ = text.size();
  source.size_bytes_ = text.size();
  source.eof_ = true;
  return source;
}

void LineSource::Refill() {
  // Keep the unfinished line, grow the buffer only when that line fills it.
  const std::size_t rest = end_ - pos_;
  if (pos_ > 0) std::memmove(storage_.data(), storage_.data() + pos_, rest);
  consumed_ += pos_;
  pos_ = 0;
  end_ = rest;
  if (end_ == storage_.size()) storage_.resize(storage_.size() * 2);
  data_ = storage_.data();
  const std::size_t got =
      std::fread(storage_.data() + end_, 1, storage_.size() - end_, file_.get());
  end_ += got;
  if (got == 0) {
    if (std::ferror(file_.get())) {
      throw InputError(name_, "byte " + std::to_string(consumed_ + end_),
                       std::string("read failed: ") + std::strerror(errno));
    }
    eof_ = true;
  }
}

bool LineSource::Next(std::string_view& line) {
  for (;;) {
    const char* begin = data_ + pos_;
    const char* newline =
        pos_ < end_ ? static_cast<const char*>(std::memchr(begin, '\n', end_ - pos_)) : nullptr;
    std::size_t length = 0;
    if (newline) {
      length = static_cast<std::size_t>(newline - begin);
      pos_ += length + 1;
    } else if (eof_) {
      if (pos_ >= end_) return false;
      length = end_ - pos_;
      pos_ = end_;
    } else {
      Refill();
      continue;
    }
    if (length > 0 && begin[length - 1] == '\r') --length;
    line = std::string_view(begin, length);
    if (line_number_++ == 0 && line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);  // BOM
    return true;
  }
}

std::string ReadWholeFile(const std::string& path) {
  LineSource source = LineSource::FromFile(path);
  std::string text;
  text.resize(source.size_bytes());
  const std::size_t got = std::fread(text.data(), 1, text.size(), source.file_.get());
  if (got != text.size()) {
    throw InputError(path, "byte " + std::to_string(got),
                     std::string("read failed: ") + std::strerror(errno));
  }
  return text;
}

std::vector<std::string> SplitNames(std::string_view line, char delimiter) {
  std::vector<std::string> names;
  FieldCursor cursor(line, delimiter);
  std::string_view field;
  while (cursor.Next(field)) {
    if (field.size() >= 2 && field.front() == '"' && field.back() == '"') {
      field = field.substr(1, field.size() - 2);
    }
    names.emplace_back(field);
  }
  return names;
}

std::string Quote(std::string_view field) {
  constexpr std::size_t kMax = 40;
  // Printable: a NUL would cut the message (what() is a C string), binary bytes garble it.
  return "'" + Printable(field, kMax) + "'";
}

std::string FormatNumber(double value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, value);
  return std::string(text, result.ptr);
}

bool IsBlankLine(std::string_view line) { return Trim(line).empty(); }

}  // namespace plumb::io::detail
