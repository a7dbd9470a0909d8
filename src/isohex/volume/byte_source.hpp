#pragma once
/// \file byte_source.hpp
/// \brief Sequential byte streams for the volume readers: a file from an offset, a memory
/// buffer, and zlib/gzip inflation of another source.
///
/// Volume data is decoded chunk by chunk from a source into the float values, so that a
/// file is never held in memory as a whole next to its decoded values, and so that gzip
/// data inflates into exactly the space the header declared and no further.

#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

struct z_stream_s;  // zlib's stream state, kept out of this header

namespace isohex::volume_detail {

/// A stream of bytes read front to back.
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  /// Reads up to `n` bytes into `out`; returns fewer only at the end of the stream.
  /// Throws isohex::Error on a read fault or corrupt compressed data.
  virtual std::size_t read(unsigned char* out, std::size_t n) = 0;
  /// Discards `n` bytes; false if the stream ended first.
  bool skip(std::size_t n);
};

/// The bytes of a file from `offset` on.
class FileSource final : public ByteSource {
 public:
  /// Opens `file`; throws isohex::Error naming it if it cannot be opened or is shorter
  /// than `offset`.
  FileSource(const std::filesystem::path& file, std::size_t offset);
  std::size_t read(unsigned char* out, std::size_t n) override;
  /// Bytes from the current position to the end of the file.
  [[nodiscard]] std::size_t remaining() const { return size_ - pos_; }

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::filesystem::path file_;
  std::unique_ptr<std::FILE, Closer> fp_;
  std::size_t size_ = 0, pos_ = 0;
};

/// A view of bytes in memory (which must outlive the source).
class MemorySource final : public ByteSource {
 public:
  explicit MemorySource(std::string_view bytes) : bytes_(bytes) {}
  std::size_t read(unsigned char* out, std::size_t n) override;

 private:
  std::string_view bytes_;
  std::size_t pos_ = 0;
};

/// Inflates the zlib or gzip stream (detected from its first bytes) that `input` holds.
/// Concatenated gzip members are read as one stream, as gzip does; bytes after the end of
/// the stream are ignored. Corrupt data and an input that ends inside the stream throw
/// isohex::Error "FILE: WHAT: ..." (`what` names the data, e.g. "gzip data").
class InflateSource final : public ByteSource {
 public:
  InflateSource(ByteSource& input, std::filesystem::path file, std::string what);
  ~InflateSource() override;
  InflateSource(const InflateSource&) = delete;
  InflateSource& operator=(const InflateSource&) = delete;
  std::size_t read(unsigned char* out, std::size_t n) override;

 private:
  bool refill();
  [[noreturn]] void fail(std::string_view what) const;

  ByteSource& input_;
  std::filesystem::path file_;
  std::string what_;
  std::unique_ptr<z_stream_s> zs_;
  std::unique_ptr<unsigned char[]> buffer_;
  bool ended_ = false, input_ended_ = false;
  std::size_t consumed_ = 0;  // compressed bytes handed to zlib, for messages
};

/// Reads until `n` bytes are in `out` or the source ends; returns the count read.
std::size_t read_full(ByteSource& source, unsigned char* out, std::size_t n);

/// The first `n` bytes of `file` (fewer if it is shorter); throws isohex::Error naming the
/// file if it cannot be read.
std::string read_prefix(const std::filesystem::path& file, std::size_t n);

/// Size of `file` in bytes; throws isohex::Error naming it if it is missing or unreadable.
std::size_t size_of_file(const std::filesystem::path& file);

}  // namespace isohex::volume_detail
