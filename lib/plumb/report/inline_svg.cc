#include "plumb/report/inline_svg.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>

#include "plumb/core/error.h"

namespace plumb::report {
namespace {

/// gnuplot's title of every SVG it writes.
constexpr std::string_view kGnuplotTitle = "<title>Gnuplot</title>";

bool IsSpace(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

/// Finds, in order, where id values and references to ids start in an SVG text: after
/// ` id='`, ` id="`, `href='#`, `href="#` (also xlink:href) and `url(#`. Each pattern's next
/// position is kept, so a pass over the text is linear in its length.
class ValueScanner {
 public:
  explicit ValueScanner(std::string_view text) : text_(text) {
    for (std::size_t p = 0; p < kPatterns; ++p) next_[p] = Find(p, 0);
  }
  /// The next value at or after `from`: its start (npos when none), its kind ('i' an id,
  /// 'r' a reference) and its closing character.
  std::size_t Next(std::size_t from, char& kind, char& close) {
    std::size_t best = std::string_view::npos, which = kPatterns;
    for (std::size_t p = 0; p < kPatterns; ++p) {
      if (next_[p] != std::string_view::npos && next_[p] < from) next_[p] = Find(p, from);
      if (next_[p] != std::string_view::npos && next_[p] < best) {
        best = next_[p];
        which = p;
      }
    }
    if (which == kPatterns) return std::string_view::npos;
    kind = which < 2 ? 'i' : 'r';
    close = kClose[which];
    return best + kText[which].size();
  }

 private:
  static constexpr std::size_t kPatterns = 5;
  static constexpr std::string_view kText[kPatterns] = {"id='", "id=\"", "href='#", "href=\"#",
                                                        "url(#"};
  static constexpr char kClose[kPatterns] = {'\'', '"', '\'', '"', ')'};
  /// Where pattern p next starts at or after `from`; an id must follow white space.
  std::size_t Find(std::size_t p, std::size_t from) const {
    for (std::size_t at = text_.find(kText[p], from); at != std::string_view::npos;
         at = text_.find(kText[p], at + 1)) {
      if (p >= 2 || (at > 0 && IsSpace(text_[at - 1]))) return at;
    }
    return std::string_view::npos;
  }
  std::string_view text_;
  std::size_t next_[kPatterns];
};

bool ValidPrefix(const std::string& prefix) {
  return std::all_of(prefix.begin(), prefix.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
  });
}

}  // namespace

std::string InlineSvg(std::string_view document, const std::string& id_prefix,
                      const std::string& name) {
  if (!ValidPrefix(id_prefix)) {
    throw Error(name + ": the id prefix '" + id_prefix + "' may hold letters, digits, - and _ only");
  }
  std::size_t begin = document.find("<svg");
  while (begin != std::string_view::npos && begin + 4 < document.size() &&
         !IsSpace(document[begin + 4]) && document[begin + 4] != '>') {
    begin = document.find("<svg", begin + 1);
  }
  const std::size_t close = document.rfind("</svg>");
  if (begin == std::string_view::npos || close == std::string_view::npos || close < begin) {
    throw Error(name + ": not an SVG document (no <svg ...> ... </svg> element)");
  }
  std::string svg(document.substr(begin, close + 6 - begin));
  if (const std::size_t t = svg.find(kGnuplotTitle); t != std::string::npos) {
    svg.erase(t, kGnuplotTitle.size());
  }
  // Pass 1: the ids defined. Pass 2: each id and each reference to one of them prefixed.
  std::set<std::string> ids;
  char kind = 0, quote = 0;
  ValueScanner first(svg);
  for (std::size_t at = first.Next(0, kind, quote); at != std::string::npos;
       at = first.Next(at, kind, quote)) {
    const std::size_t end = svg.find(quote, at);
    if (end == std::string::npos) break;
    if (kind == 'i') ids.insert(svg.substr(at, end - at));
  }
  std::string out;
  out.reserve(svg.size() + 64);
  std::size_t copied = 0;
  ValueScanner second(svg);
  for (std::size_t at = second.Next(0, kind, quote); at != std::string::npos;
       at = second.Next(at, kind, quote)) {
    const std::size_t end = svg.find(quote, at);
    if (end == std::string::npos) break;
    if (ids.count(svg.substr(at, end - at)) == 0) continue;  // e.g. an external reference
    out.append(svg, copied, at - copied);
    out += id_prefix;
    copied = at;
  }
  out.append(svg, copied, std::string::npos);
  return out;
}

std::vector<InlineFigure> TakeSvgFiles(const std::string& folder,
                                       const std::vector<std::string>& names) {
  std::vector<InlineFigure> out;
  for (const std::string& file : names) {
    const std::filesystem::path path = std::filesystem::path(folder) / file;
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path.string() + ": cannot read the figure gnuplot wrote");
    const std::string document((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::string stem = std::filesystem::path(file).stem().string();
    for (char& c : stem) {
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-') c = '_';
    }
    out.push_back({file, InlineSvg(document, stem + "-", path.string())});
    in.close();
    std::error_code ec;
    std::filesystem::remove(path, ec);
    if (ec) throw Error(path.string() + ": cannot remove it after putting it in the page: " + ec.message());
  }
  return out;
}

}  // namespace plumb::report
