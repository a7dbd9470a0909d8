#include "isohex/io/vtk_xml_data.hpp"

#include "isohex/io/base64.hpp"
#include "isohex/io/text_scanner.hpp"

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <climits>
#include <optional>
#include <string>

namespace isohex::io::vtkxml {

namespace {

/// Deflate cannot expand data more than about 1032:1; a block claiming more is corrupt.
constexpr std::uint64_t kMaxZlibRatio = 1032;
/// Blocks are inflated in parallel in groups of about this many output bytes, so that the
/// output grows only as fast as real data arrives.
constexpr std::size_t kGroupBytes = std::size_t{8} << 20;

struct ScalarInfo {
  std::string_view name;
  Scalar scalar;
  std::size_t size;
  bool integer;
};

constexpr ScalarInfo kScalars[] = {
    {"Int8", Scalar::Int8, 1, true},       {"UInt8", Scalar::UInt8, 1, true},
    {"Int16", Scalar::Int16, 2, true},     {"UInt16", Scalar::UInt16, 2, true},
    {"Int32", Scalar::Int32, 4, true},     {"UInt32", Scalar::UInt32, 4, true},
    {"Int64", Scalar::Int64, 8, true},     {"UInt64", Scalar::UInt64, 8, true},
    {"Float32", Scalar::Float32, 4, false}, {"Float64", Scalar::Float64, 8, false}};

const ScalarInfo& info(Scalar s) { return kScalars[static_cast<int>(s)]; }

/// Reverses the bytes of each of `count` values of `size` bytes.
void swap_bytes(unsigned char* p, std::size_t count, std::size_t size) {
  if (size == 1) return;
  for (std::size_t i = 0; i < count; ++i, p += size) std::reverse(p, p + size);
}

/// Inflates one complete zlib stream into exactly `out_size` bytes; an error text or "".
std::string inflate_block(const unsigned char* in, std::size_t in_size, unsigned char* out, std::size_t out_size) {
  if (in_size > UINT_MAX || out_size > UINT_MAX) return "block larger than 4 GiB";
  z_stream zs{};
  if (inflateInit(&zs) != Z_OK) return "zlib initialisation failed";
  zs.next_in = const_cast<unsigned char*>(in);  // zlib's API is not const-correct
  zs.avail_in = static_cast<uInt>(in_size);
  zs.next_out = out;
  zs.avail_out = static_cast<uInt>(out_size);
  const int r = inflate(&zs, Z_FINISH);
  std::string error;
  if (r == Z_STREAM_END) {
    if (zs.avail_out != 0)
      error = fmt::format("inflates to {} bytes, not the {} its header declares", out_size - zs.avail_out, out_size);
    else if (zs.avail_in != 0)
      error = fmt::format("{} stray bytes after the end of the zlib stream", zs.avail_in);
  } else if (r == Z_DATA_ERROR || r == Z_NEED_DICT) {
    error = fmt::format("corrupt zlib data ({})", zs.msg ? zs.msg : "invalid stream");
  } else if (zs.avail_out == 0) {
    error = fmt::format("inflates to more than the {} bytes its header declares", out_size);
  } else {
    error = "zlib data ends early (truncated block)";
  }
  inflateEnd(&zs);
  return error;
}

/// Where binary bytes come from: raw bytes of the file, or base64 text decoded on demand.
class Source {
 public:
  Source(std::string_view raw, std::size_t file_offset) : raw_(raw), raw_offset_(file_offset) {}
  explicit Source(Base64Reader reader) : base64_(std::move(reader)) {}

  [[nodiscard]] bool is_raw() const { return !base64_; }
  [[nodiscard]] std::size_t max_remaining() const { return base64_ ? base64_->max_remaining() : raw_.size() - pos_; }
  [[nodiscard]] std::size_t file_offset() const { return base64_ ? base64_->file_offset() : raw_offset_ + pos_; }
  /// False (and nothing read) when fewer than `n` raw bytes remain.
  bool read(unsigned char* out, std::size_t n) {
    if (base64_) {
      base64_->read(out, n);
      return true;
    }
    const std::string_view v = take(n);
    if (v.size() != n) return false;
    std::memcpy(out, v.data(), n);
    return true;
  }
  /// The next `n` raw bytes in place, or an empty view if fewer remain (raw sources only).
  std::string_view take(std::size_t n) {
    if (n > raw_.size() - pos_) return {};
    const std::string_view v = raw_.substr(pos_, n);
    pos_ += n;
    return v;
  }

 private:
  std::string_view raw_;
  std::size_t raw_offset_ = 0, pos_ = 0;
  std::optional<Base64Reader> base64_;
};

}  // namespace

bool scalar_from_name(std::string_view name, Scalar& out) {
  for (const ScalarInfo& s : kScalars)
    if (s.name == name) {
      out = s.scalar;
      return true;
    }
  return false;
}

std::size_t scalar_size(Scalar s) { return info(s).size; }
bool is_integer(Scalar s) { return info(s).integer; }

/// Decodes one <DataArray>.
class Decoder {
 public:
  Decoder(const xml::Element& e, std::size_t count, const Context& c) : e_(e), count_(count), c_(c) {
    const std::string* name = e.attribute("Name");
    label_ = fmt::format("DataArray '{}'", name ? *name : std::string("(unnamed)"));
    const std::string* type = e.attribute("type");
    if (!type) fail(e.offset, "has no type attribute");
    if (!scalar_from_name(*type, a_.type_))
      fail(e.offset, fmt::format("has unsupported type '{}' (expected Int8...UInt64, Float32 or Float64)", *type));
    if (count_ > SIZE_MAX / 8) fail(e.offset, fmt::format("declares an impossible {} values", count_));
    bytes_ = count_ * scalar_size(a_.type_);
    a_.size_ = count_;
  }

  Array run() {
    const std::string* format = e_.attribute("format");
    if (!format) fail(e_.offset, "has no format attribute");
    if (*format == "ascii") {
      ascii();
    } else if (*format == "binary") {
      inline_binary();
    } else if (*format == "appended") {
      appended();
    } else {
      fail(e_.offset, fmt::format("has unknown format '{}' (expected ascii, binary or appended)", *format));
    }
    return std::move(a_);
  }

 private:
  /// "line L (byte B)" inside XML text; just the byte offset inside raw appended bytes.
  std::string where(std::size_t offset) const {
    if (c_.has_appended && !c_.appended_base64 && offset >= c_.appended_begin)
      return fmt::format("byte {}", offset);
    return xml::position(c_.text, offset);
  }

  [[noreturn]] void fail(std::size_t offset, std::string_view what) const {
    parse_error(c_.file, where(offset), fmt::format("{} {}", label_, what));
  }

  std::string expected_bytes() const {
    return fmt::format("{} values of {} need {}", count_, info(a_.type_).name, bytes_);
  }

  /// The element's character data: one non-blank run, or none.
  std::optional<std::pair<std::size_t, std::size_t>> text() const {
    if (e_.text.empty()) return std::nullopt;
    if (e_.text.size() > 1) fail(e_.text[1].first, "has its data split by child elements");
    return e_.text.front();
  }

  void ascii() {
    a_.format_ = "ascii";
    const auto t = text();
    if (!t) {
      if (count_ != 0) fail(e_.offset, fmt::format("has no data; {} values expected", count_));
      return;
    }
    const auto [begin, end] = *t;
    // Each value takes at least one character and one separator.
    if (count_ > (end - begin + 1) / 2)
      fail(begin, fmt::format("should hold {} values but its text has room for at most {}", count_,
                              (end - begin + 1) / 2));
    TextScanner sc(c_.text.substr(0, end), c_.file, begin);
    if (is_integer(a_.type_))
      parse_ascii<std::int64_t>(sc, Scalar::Int64);
    else
      parse_ascii<double>(sc, Scalar::Float64);
  }

  template <class T>
  void parse_ascii(TextScanner& sc, Scalar stored_as) {
    a_.type_ = stored_as;
    a_.storage_.resize(count_ * sizeof(T));
    T* out = reinterpret_cast<T*>(a_.storage_.data());
    for (std::size_t i = 0; i < count_; ++i) {
      const std::string_view tok = sc.next();
      if (tok.empty()) sc.fail(fmt::format("{} ends after {} of its {} values", label_, i, count_));
      bool ok;
      if constexpr (std::is_same_v<T, double>)
        ok = parse_double(tok, out[i]);
      else
        ok = parse_int(tok, out[i]);
      if (!ok)
        sc.fail(fmt::format("{}: value {} '{}' is not {}", label_, i, tok.substr(0, 40),
                            std::is_same_v<T, double> ? "a finite number" : "an integer"));
    }
    if (!sc.next().empty()) sc.fail(fmt::format("{} holds more than the {} values expected", label_, count_));
    a_.data_ = a_.storage_.data();
  }

  void inline_binary() {
    a_.format_ = "binary";
    const auto t = text();
    if (!t) {
      if (count_ != 0) fail(e_.offset, fmt::format("has no data; {} values expected", count_));
      return;
    }
    Source src(Base64Reader(c_.text.substr(t->first, t->second - t->first), t->first, c_.file));
    binary(src);
  }

  void appended() {
    if (!c_.has_appended) fail(e_.offset, "is in appended format, but the file has no <AppendedData>");
    a_.format_ = c_.appended_base64 ? "appended base64" : "appended raw";
    const std::string* offset_attr = e_.attribute("offset");
    std::int64_t offset = -1;
    if (!offset_attr || !parse_int(*offset_attr, offset) || offset < 0)
      fail(e_.offset, "needs a non-negative integer offset attribute");
    const std::string_view data = c_.text.substr(c_.appended_begin);
    if (static_cast<std::uint64_t>(offset) > data.size())
      fail(e_.offset, fmt::format("offset {} lies beyond the end of the appended data ({} bytes; file truncated?)",
                                  offset, data.size()));
    const auto off = static_cast<std::size_t>(offset);
    if (c_.appended_base64) {
      Source src(Base64Reader(data.substr(off), c_.appended_begin + off, c_.file));
      binary(src);
    } else {
      Source src(data.substr(off), c_.appended_begin + off);
      binary(src);
    }
  }

  void read(Source& src, unsigned char* out, std::size_t n, std::string_view what) {
    const std::size_t at = src.file_offset();
    if (!src.read(out, n))
      fail(at, fmt::format("{} needs {} bytes but only {} remain (file truncated?)", what, n, src.max_remaining()));
  }

  std::uint64_t word(Source& src, std::string_view what) {
    unsigned char b[8] = {};
    read(src, b, c_.header_bytes, what);
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < c_.header_bytes; ++i) {
      const std::size_t k = c_.big_endian ? i : c_.header_bytes - 1 - i;
      v = (v << 8) | b[k];
    }
    return v;
  }

  void binary(Source& src) {
    if (c_.zlib)
      compressed(src);
    else
      uncompressed(src);
    const bool native_big = std::endian::native == std::endian::big;
    if (c_.big_endian != native_big) {
      if (a_.storage_.empty() && bytes_ != 0) a_.storage_.assign(a_.data_, a_.data_ + bytes_);
      swap_bytes(a_.storage_.data(), count_, scalar_size(a_.type_));
      a_.data_ = a_.storage_.data();
    }
  }

  void uncompressed(Source& src) {
    const std::size_t at = src.file_offset();
    const std::uint64_t declared = word(src, "the size header");
    if (declared != bytes_)
      fail(at, fmt::format("size header declares {} bytes, but {}", declared, expected_bytes()));
    if (src.is_raw()) {
      const std::string_view v = src.take(bytes_);
      if (v.size() != bytes_)
        fail(src.file_offset(), fmt::format("needs {} bytes but only {} remain (file truncated?)", bytes_,
                                            src.max_remaining()));
      a_.data_ = reinterpret_cast<const unsigned char*>(v.data());
      return;
    }
    if (bytes_ > src.max_remaining())
      fail(src.file_offset(), fmt::format("needs {} bytes but its base64 text holds at most {} (file truncated?)",
                                          bytes_, src.max_remaining()));
    a_.storage_.resize(bytes_);
    read(src, a_.storage_.data(), bytes_, "the data");
    a_.data_ = a_.storage_.data();
  }

  void compressed(Source& src) {
    const std::size_t at = src.file_offset();
    const std::uint64_t nblocks = word(src, "the zlib header");
    const std::uint64_t block_size = word(src, "the zlib header");
    const std::uint64_t last_size = word(src, "the zlib header");
    if (nblocks > src.max_remaining() / c_.header_bytes)
      fail(at, fmt::format("zlib header declares {} blocks, more than the file can hold (corrupt or truncated)", nblocks));
    std::vector<std::uint64_t> csize(static_cast<std::size_t>(nblocks));
    for (auto& s : csize) s = word(src, "the zlib block sizes");
    const std::uint64_t total = total_size(at, nblocks, block_size, last_size);
    if (total != bytes_) fail(at, fmt::format("zlib header declares {} uncompressed bytes, but {}", total, expected_bytes()));
    std::uint64_t csum = 0;
    for (std::size_t i = 0; i < csize.size(); ++i) {
      const std::uint64_t usize = i + 1 == csize.size() && last_size ? last_size : block_size;
      if (csize[i] > src.max_remaining() || usize > kMaxZlibRatio * csize[i] + 64)
        fail(at, fmt::format("zlib block {} of {} declares {} compressed bytes for {} bytes of data: corrupt header "
                             "or truncated file", i, nblocks, csize[i], usize));
      csum += csize[i];
    }
    if (csum > src.max_remaining())
      fail(at, fmt::format("zlib blocks total {} bytes but only {} remain (file truncated?)", csum, src.max_remaining()));
    const std::size_t data_at = src.file_offset();
    std::vector<unsigned char> decoded;
    const unsigned char* in = nullptr;
    if (src.is_raw()) {
      in = reinterpret_cast<const unsigned char*>(src.take(csum).data());
    } else {
      decoded.resize(csum);
      read(src, decoded.data(), csum, "the zlib blocks");
      in = decoded.data();
    }
    inflate_all(in, data_at, csize, static_cast<std::size_t>(block_size));
  }

  std::uint64_t total_size(std::size_t at, std::uint64_t nblocks, std::uint64_t block_size, std::uint64_t last_size) const {
    if (nblocks == 0) return 0;
    if (block_size == 0) fail(at, "zlib header declares a block size of 0");
    if (last_size > block_size)
      fail(at, fmt::format("zlib header declares a last block of {} bytes, larger than the block size {}", last_size,
                           block_size));
    const std::uint64_t last = last_size ? last_size : block_size;
    if (nblocks - 1 > (UINT64_MAX - last) / block_size) fail(at, "zlib header sizes overflow");
    return (nblocks - 1) * block_size + last;
  }

  /// Inflates the blocks in parallel, a group at a time, growing the output as it goes.
  void inflate_all(const unsigned char* in, std::size_t in_at, const std::vector<std::uint64_t>& csize,
                   std::size_t block_size) {
    const std::size_t n = csize.size();
    std::vector<std::size_t> in_offset(n + 1, 0);
    for (std::size_t i = 0; i < n; ++i) in_offset[i + 1] = in_offset[i] + csize[i];
    std::vector<std::string> errors(n);
    for (std::size_t first = 0; first < n;) {
      std::size_t last = first, grow = 0;
      while (last < n && (last == first || grow < kGroupBytes)) {
        grow += std::min(block_size, bytes_ - last * block_size);
        ++last;
      }
      a_.storage_.resize(a_.storage_.size() + grow);
      unsigned char* out = a_.storage_.data();
      tbb::parallel_for(first, last, [&](std::size_t i) {
        const std::size_t usize = std::min(block_size, bytes_ - i * block_size);
        errors[i] = inflate_block(in + in_offset[i], csize[i], out + i * block_size, usize);
      });
      for (std::size_t i = first; i < last; ++i)
        if (!errors[i].empty()) fail(in_at + in_offset[i], fmt::format("zlib block {} of {}: {}", i, n, errors[i]));
      first = last;
    }
    a_.data_ = a_.storage_.data();
  }

  const xml::Element& e_;
  std::size_t count_;
  const Context& c_;
  std::string label_;
  std::size_t bytes_ = 0;
  Array a_;
};

Array decode(const xml::Element& element, std::size_t count, const Context& context) {
  return Decoder(element, count, context).run();
}

}  // namespace isohex::io::vtkxml
