#pragma once
/// \file format_support.hpp
/// \brief Small pieces shared by the legacy VTK, MEDIT and Abaqus readers and writers:
/// case-insensitive keywords, printable tokens for messages, a pre-write mesh check and
/// buffered text / big-endian output.

#include "isohex/io/big_endian.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/hex_mesh.hpp"

#include <fmt/format.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

namespace isohex::io {

/// ASCII case-insensitive equality (file keywords are ASCII).
bool iequals(std::string_view a, std::string_view b);

/// True if `text` starts with `prefix`, ignoring ASCII case.
bool istarts_with(std::string_view text, std::string_view prefix);

/// `token` as it may be quoted in a message: at most 40 characters, bytes that are not
/// printable ASCII shown as \xNN (binary files put arbitrary bytes where keywords belong).
std::string printable(std::string_view token);

/// Throws isohex::Error naming `file` unless `mesh` can be written as it is: every hex
/// vertex id in range, finite coordinates, `blocks`/`fixed` empty or one per hex/vertex.
void check_mesh_for_writing(const std::filesystem::path& file, const HexMesh& mesh);

/// Throws isohex::Error naming `file` for a WriteOptions field whose name is not letters,
/// digits and '_' (starting with a letter), clashes with another or with "block" / "fixed", or
/// whose values do not match the hexes (cell fields) or vertices (point fields) one to one.
void check_fields_for_writing(const std::filesystem::path& file, const HexMesh& mesh, const WriteOptions& options);

/// Formats text into a buffer and hands it to a stream in large chunks.
class TextOut {
 public:
  explicit TextOut(std::ostream& out) : out_(out) {}
  TextOut(const TextOut&) = delete;
  TextOut& operator=(const TextOut&) = delete;

  template <class... Args>
  void print(fmt::format_string<Args...> format, Args&&... args) {
    fmt::format_to(std::back_inserter(buffer_), format, std::forward<Args>(args)...);
    if (buffer_.size() >= kChunk) flush();
  }
  /// Writes what is buffered; call once at the end.
  void flush();

 private:
  static constexpr std::size_t kChunk = std::size_t{1} << 20;
  std::ostream& out_;
  fmt::memory_buffer buffer_;
};

/// Collects big-endian values and hands them to a stream in large chunks.
class BigEndianOut {
 public:
  explicit BigEndianOut(std::ostream& out) : out_(out) { buffer_.reserve(kChunk + 16); }
  BigEndianOut(const BigEndianOut&) = delete;
  BigEndianOut& operator=(const BigEndianOut&) = delete;

  template <class T>
  void put(T value) {
    const std::size_t at = buffer_.size();
    buffer_.resize(at + sizeof(T));
    store_be(buffer_.data() + at, value);
    if (buffer_.size() >= kChunk) flush();
  }
  /// Writes what is buffered; call once at the end.
  void flush();

 private:
  static constexpr std::size_t kChunk = std::size_t{1} << 20;
  std::ostream& out_;
  std::vector<unsigned char> buffer_;
};

}  // namespace isohex::io
