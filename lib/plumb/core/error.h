// plumb/core/error.h — the one exception type of the library.
//
// The library never prints and never calls exit(); it throws plumb::Error with a message that
// names the file, the place (line or byte offset) and what was expected (SPEC section 8).
// Only the front ends (the command's `main`, the Python module) catch it.
//
// A message that points the user to an option names it through OptionText (option_name.h),
// spelled by the front end; the error also carries those options as data (options()), in the
// order the message names them, so that a front end can act on them without reading the text
// (Python: the exception's .options, its keywords). The kind of error is its class, its code:
// Error (a request the library cannot carry out), InputError (a file, with its place) and
// InsufficientDataError (the data cannot support the model), raised in Python as plumb.Error,
// plumb.InputError and plumb.InsufficientDataError. A program acts on the class and the
// options; the message, which names the file and the place, is for the user.
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "plumb/core/option_name.h"

namespace plumb {

/// `text` as a message may quote it: control bytes (NUL included, tab and newline excepted)
/// and bytes that are not part of valid UTF-8 written as \xNN, cut after `max_chars` bytes
/// of the input with "..." appended. A file's binary content then reads as bytes instead of
/// garbling the terminal or cutting the message at a NUL.
std::string Printable(std::string_view text, std::size_t max_chars);

/// The message is kept printable (see Printable): a NUL quoted from a file would otherwise cut
/// what() short, and binary bytes would garble the terminal.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(Printable(what, kMaxMessage)) {}
  /// `options`: the options `what` names (through OptionText), in its order.
  Error(const std::string& what, std::vector<Option> options)
      : std::runtime_error(Printable(what, kMaxMessage)), options_(std::move(options)) {}

  /// The options the message points the user to; empty when it names none.
  const std::vector<Option>& options() const { return options_; }

  /// Longest message kept, bytes.
  static constexpr std::size_t kMaxMessage = 16000;

 private:
  std::vector<Option> options_;
};

/// Error about an input file. `where` is e.g. "line 12" or "byte 4096"; may be empty.
class InputError : public Error {
 public:
  InputError(const std::string& file, const std::string& where, const std::string& what,
             std::vector<Option> options = {})
      : Error(file + (where.empty() ? "" : ":" + where) + ": " + what, std::move(options)),
        file_(file), where_(where) {}
  const std::string& file() const { return file_; }
  const std::string& where() const { return where_; }

 private:
  std::string file_;
  std::string where_;
};

/// Error raised when the data cannot support the requested model; the message says what is
/// missing and what to record.
class InsufficientDataError : public Error {
 public:
  explicit InsufficientDataError(const std::string& what, std::vector<Option> options = {})
      : Error(what, std::move(options)) {}
};


/// The error for a JSON file at `path` that its parser refused, from the parser's own message
/// (`parser_what`, nlohmann's "[json.exception.parse_error.101] parse error at line 3, column
/// 7: syntax error ..." or "[json.exception.out_of_range.406] number overflow parsing
/// '1e400'"): the library's tag dropped, the line and column as the place, a number beyond a
/// double said so.
InputError JsonTextError(const std::string& path, std::string_view parser_what);

/// `parse()` (a JSON parser's call), its exceptions turned into JsonTextError naming `path`:
/// the one way plumb's readers of JSON files parse them.
///   const nlohmann::json doc = ParseJsonText(path, [&] { return nlohmann::json::parse(text); });
template <typename Parse>
auto ParseJsonText(const std::string& path, Parse&& parse) -> decltype(parse()) {
  try {
    return parse();
  } catch (const InputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw JsonTextError(path, e.what());
  }
}

/// A number as messages print it: 6 significant digits ("1e+300", "0.0199", "200"), never
/// std::to_string's fixed 6 decimals (309 digits for 1e300, "0.000000" for 1e-9); `digits`
/// significant digits where a message wants fewer or more ("%.*g", 4 for the gates' figures).
std::string Number(double value, int digits = 6);

}  // namespace plumb
