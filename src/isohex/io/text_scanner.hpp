#pragma once
/// \file text_scanner.hpp
/// \brief Whitespace-separated token reading with line numbers, for the ASCII readers.
///
/// Every failure throws isohex::Error as "FILE: line N: what is wrong", so readers never
/// need their own error formatting for text formats.

#include "isohex/error.hpp"

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace isohex::io {

/// Throws isohex::Error "FILE: WHERE: WHAT".
[[noreturn]] void parse_error(const std::filesystem::path& file, std::string_view where, std::string_view what);

/// A cursor over a text buffer (which must outlive it).
class TextScanner {
 public:
  TextScanner(std::string_view text, std::filesystem::path file, std::size_t offset = 0);

  /// The next whitespace-separated token, or an empty view at the end of the text.
  std::string_view next();
  /// Like next(), but fails with "unexpected end of file, expected WHAT" at the end.
  std::string_view expect(std::string_view what);
  /// The next token as a finite double / an integer in [lo, hi]; `what` names the field.
  double next_double(std::string_view what);
  std::int64_t next_int(std::string_view what, std::int64_t lo = INT64_MIN, std::int64_t hi = INT64_MAX);
  /// The rest of the current line (without the newline), and moves past it.
  std::string_view rest_of_line();
  /// Skips whitespace (including newlines); true if text remains.
  bool skip_space();
  [[nodiscard]] bool at_end() const { return pos_ >= text_.size(); }
  /// 1-based line number of the cursor.
  [[nodiscard]] std::size_t line() const { return line_; }
  /// Bytes after the cursor.
  [[nodiscard]] std::size_t remaining() const { return text_.size() - pos_; }
  /// Byte offset of the cursor into the text.
  [[nodiscard]] std::size_t offset() const { return pos_; }
  /// Moves the cursor to `offset` (line counting continues from the current line).
  void seek(std::size_t offset);
  [[nodiscard]] const std::filesystem::path& file() const { return file_; }
  /// Throws "FILE: line N: WHAT".
  [[noreturn]] void fail(std::string_view what) const;

 private:
  std::string_view text_;
  std::filesystem::path file_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
};

/// Parses a whole token as a finite double / integer; false if it is not one.
bool parse_double(std::string_view token, double& value);
bool parse_int(std::string_view token, std::int64_t& value);

}  // namespace isohex::io
