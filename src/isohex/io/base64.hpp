#pragma once
/// \file base64.hpp
/// \brief Incremental base64 decoding of VTK XML `binary` and encoded `appended` data.

#include <cstddef>
#include <filesystem>
#include <string_view>

namespace isohex::io {

/// Decodes base64 text on demand, a few bytes at a time or in bulk.
///
/// Whitespace is skipped. '=' padding may also end a group in mid-stream, because VTK
/// encodes a compressed array's block header and its data as separate base64 runs. The
/// text ends at its end or at the first '<' (the closing tag of the element holding it).
class Base64Reader {
 public:
  /// `text` is the encoded text, found at byte `file_offset` of `file` (for messages).
  Base64Reader(std::string_view text, std::size_t file_offset, const std::filesystem::path& file);

  /// Decodes exactly `n` bytes into `out`; throws isohex::Error naming the file and byte
  /// offset if the text ends first or holds a character that is not base64.
  void read(unsigned char* out, std::size_t n);

  /// An upper bound on the bytes still decodable, to check declared sizes before allocating.
  [[nodiscard]] std::size_t max_remaining() const { return pending_size_ + (text_.size() - pos_) / 4 * 3 + 3; }

  /// Byte offset in the file of the next character to decode.
  [[nodiscard]] std::size_t file_offset() const { return file_offset_ + pos_; }

 private:
  /// Decodes the next group of 4 symbols (1 to 3 bytes) into pending_.
  void next_group(std::size_t bytes_wanted);
  [[noreturn]] void fail(std::size_t at, std::string_view what) const;

  std::string_view text_;
  std::size_t file_offset_;
  const std::filesystem::path& file_;
  std::size_t pos_ = 0;
  unsigned char pending_[3] = {0, 0, 0};
  std::size_t pending_begin_ = 0, pending_size_ = 0;
};

}  // namespace isohex::io
