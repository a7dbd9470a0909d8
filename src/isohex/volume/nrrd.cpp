// NRRD (teem's "nearly raw raster data", http://teem.sourceforge.net/nrrd/format.html):
// attached (.nrrd) and detached (.nhdr) headers; raw, gzip and ascii encodings; one data
// file, a LIST of them, or a numbered "format min max step" series. Writer: raw, little
// endian, with space directions and origin so that Slicer, ITK and VTK place it alike.
#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/format_support.hpp"
#include "isohex/io/text_scanner.hpp"
#include "isohex/volume/decode.hpp"
#include "isohex/volume/formats.hpp"

#include <fmt/format.h>

#include <map>
#include <optional>
#include <ostream>
#include <vector>

namespace isohex::volume_detail {

namespace {

namespace fs = std::filesystem;

enum class Encoding { raw, gzip, ascii };

struct NrrdHeader {
  std::optional<ScalarType> type;
  std::optional<std::array<std::int64_t, 3>> sizes;
  std::optional<Vec3> spacings, origin, axis_mins;
  std::optional<Eigen::Matrix3d> directions;
  std::optional<bool> big_endian;
  Encoding encoding = Encoding::raw;
  bool has_encoding = false;
  std::vector<fs::path> data_files;  // empty: the data follows the header
  std::int64_t line_skip = 0, byte_skip = 0;
  std::size_t data_offset = 0;  // attached data: where it starts in the file
};

/// NRRD's type names (all spellings teem accepts for the 8 supported types).
const std::map<std::string, ScalarType>& type_names() {
  static const std::map<std::string, ScalarType> names = {{"uchar", ScalarType::u8},
                                                          {"unsigned char", ScalarType::u8},
                                                          {"uint8", ScalarType::u8},
                                                          {"uint8_t", ScalarType::u8},
                                                          {"signed char", ScalarType::i8},
                                                          {"int8", ScalarType::i8},
                                                          {"int8_t", ScalarType::i8},
                                                          {"ushort", ScalarType::u16},
                                                          {"unsigned short", ScalarType::u16},
                                                          {"unsigned short int", ScalarType::u16},
                                                          {"uint16", ScalarType::u16},
                                                          {"uint16_t", ScalarType::u16},
                                                          {"short", ScalarType::i16},
                                                          {"short int", ScalarType::i16},
                                                          {"signed short", ScalarType::i16},
                                                          {"signed short int", ScalarType::i16},
                                                          {"int16", ScalarType::i16},
                                                          {"int16_t", ScalarType::i16},
                                                          {"uint", ScalarType::u32},
                                                          {"unsigned int", ScalarType::u32},
                                                          {"uint32", ScalarType::u32},
                                                          {"uint32_t", ScalarType::u32},
                                                          {"int", ScalarType::i32},
                                                          {"signed int", ScalarType::i32},
                                                          {"int32", ScalarType::i32},
                                                          {"int32_t", ScalarType::i32},
                                                          {"float", ScalarType::f32},
                                                          {"double", ScalarType::f64}};
  return names;
}

const char* nrrd_type_name(ScalarType t) {
  switch (t) {
    case ScalarType::u8:
      return "uint8";
    case ScalarType::i8:
      return "int8";
    case ScalarType::u16:
      return "uint16";
    case ScalarType::i16:
      return "int16";
    case ScalarType::u32:
      return "uint32";
    case ScalarType::i32:
      return "int32";
    case ScalarType::f32:
      return "float";
    case ScalarType::f64:
      break;
  }
  return "double";
}

std::vector<std::string_view> split_blanks(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t pos = 0;
  while (pos < s.size()) {
    while (pos < s.size() && (s[pos] == ' ' || s[pos] == '\t')) ++pos;
    std::size_t end = pos;
    while (end < s.size() && s[end] != ' ' && s[end] != '\t') ++end;
    if (end > pos) out.push_back(s.substr(pos, end - pos));
    pos = end;
  }
  return out;
}

/// "(x,y,z)" as a vector.
std::optional<Vec3> parse_vector(std::string_view token) {
  if (token.size() < 2 || token.front() != '(' || token.back() != ')') return std::nullopt;
  double v[3];
  if (!parse_numbers(token.substr(1, token.size() - 2), v, 3, true)) return std::nullopt;
  return Vec3(v[0], v[1], v[2]);
}

/// printf-style "%d" with optional zero padding and width, the only conversion NRRD's
/// numbered data file series use; nullopt for anything else.
std::optional<std::string> format_series_name(std::string_view pattern, std::int64_t n) {
  std::string out;
  bool converted = false;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') {
      out += pattern[i];
      continue;
    }
    if (++i < pattern.size() && pattern[i] == '%') {
      out += '%';
      continue;
    }
    bool zero = false;
    int width = 0;
    if (i < pattern.size() && pattern[i] == '0') zero = true, ++i;
    while (i < pattern.size() && pattern[i] >= '0' && pattern[i] <= '9' && width < 100)
      width = width * 10 + (pattern[i++] - '0');
    if (i >= pattern.size() || pattern[i] != 'd' || converted) return std::nullopt;
    std::string digits = std::to_string(n < 0 ? -n : n);
    const std::size_t sign = n < 0 ? 1 : 0;
    if (digits.size() + sign < static_cast<std::size_t>(width))
      digits.insert(0, static_cast<std::size_t>(width) - digits.size() - sign, zero ? '0' : ' ');
    out += (n < 0 ? "-" : "") + digits;
    converted = true;
  }
  if (!converted) return std::nullopt;
  return out;
}

class HeaderParser {
 public:
  HeaderParser(const fs::path& file, std::string_view text, bool whole) : file_(file), text_(text), whole_(whole) {}

  NrrdHeader run() {
    std::size_t pos = 0;
    const std::string_view magic = next_line(pos);
    if (magic.size() < 5 || magic.substr(0, 4) != "NRRD")
      fail_line(1, "not a NRRD file: the first line should be the magic NRRD000X");
    std::size_t line = 1;
    bool ended = false;
    while (pos < text_.size()) {
      const std::string_view raw = next_line(pos);
      ++line;
      if (raw.empty()) {  // the blank line that ends an attached header
        ended = true;
        break;
      }
      if (raw.front() == '#') continue;
      if (list_) {
        h_.data_files.push_back(resolve(trim(raw)));
        continue;
      }
      field(raw, line);
    }
    if (!ended && !whole_) fail_line(line, "header does not end within the first megabyte");
    h_.data_offset = pos;
    if (h_.data_files.empty() && (list_ || data_file_seen_)) fail_field("data file", "names no data files");
    if (!ended && h_.data_files.empty()) fail_line(line, "the header has no data file and no blank line before data");
    check();
    return h_;
  }

 private:
  /// The next line without its terminator ("\n" or "\r\n"); advances `pos` past it.
  std::string_view next_line(std::size_t& pos) const {
    std::size_t end = text_.find('\n', pos);
    if (end == std::string_view::npos) end = text_.size();
    std::string_view l = text_.substr(pos, end - pos);
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    pos = std::min(end + 1, text_.size());
    return l;
  }

  [[noreturn]] void fail_line(std::size_t line, std::string_view what) const {
    fail(file_, fmt::format("line {}", line), what);
  }
  [[noreturn]] void fail_field(std::string_view name, std::string_view what) const {
    fail(file_, fmt::format("field '{}'", name), what);
  }

  fs::path resolve(std::string_view name) const {
    fs::path p{std::string(name)};
    return p.is_absolute() ? p : file_.parent_path() / p;
  }

  void field(std::string_view raw, std::size_t line) {
    const std::size_t colon = raw.find(':');
    if (colon == std::string_view::npos)
      fail_line(line, fmt::format("'{}' is not a 'field: value' line", io::printable(raw)));
    if (colon + 1 < raw.size() && raw[colon + 1] == '=') return;  // key:=value metadata
    const std::string name = lowercase(trim(raw.substr(0, colon)));
    const std::string_view value = trim(raw.substr(colon + 1));
    const std::vector<std::string_view> tokens = split_blanks(value);
    if (name == "type") {
      const auto it = type_names().find(lowercase(value));
      if (it == type_names().end())
        fail_field(name, fmt::format("unsupported type '{}' (isohex reads the 8- to 32-bit integer types, float and "
                                     "double)",
                                     io::printable(value)));
      h_.type = it->second;
    } else if (name == "dimension") {
      std::int64_t d = 0;
      if (!io::parse_int(value, d)) fail_field(name, fmt::format("'{}' is not an integer", io::printable(value)));
      if (d != 3) fail_field(name, fmt::format("isohex reads 3-D volumes; this one has dimension {}", d));
      dimension_seen_ = true;
    } else if (name == "sizes") {
      std::array<std::int64_t, 3> s{};
      if (tokens.size() != 3) fail_field(name, fmt::format("needs 3 sizes, found {}", tokens.size()));
      for (int a = 0; a < 3; ++a)
        if (!io::parse_int(tokens[a], s[a]))
          fail_field(name, fmt::format("'{}' is not an integer", io::printable(tokens[a])));
      h_.sizes = s;
    } else if (name == "spacings") {
      if (tokens.size() != 3) fail_field(name, fmt::format("needs 3 spacings, found {}", tokens.size()));
      Vec3 s;
      for (int a = 0; a < 3; ++a) {
        if (lowercase(tokens[a]) == "nan")
          s[a] = 1;  // NRRD's "unknown": unit spacing
        else if (!io::parse_double(tokens[a], s[a]))
          fail_field(name, fmt::format("'{}' is not a number", io::printable(tokens[a])));
      }
      h_.spacings = s;
    } else if (name == "space directions") {
      if (tokens.size() != 3) fail_field(name, fmt::format("needs 3 vectors, found {}", tokens.size()));
      Eigen::Matrix3d m;
      for (int a = 0; a < 3; ++a) {
        const auto v = parse_vector(tokens[a]);
        if (!v)
          fail_field(name, fmt::format("'{}' is not a 3-D vector (x,y,z); every axis must be spatial",
                                       io::printable(tokens[a])));
        m.col(a) = *v;
      }
      h_.directions = m;
    } else if (name == "space origin") {
      const auto v = parse_vector(value);
      if (!v) fail_field(name, fmt::format("'{}' is not a 3-D vector (x,y,z)", io::printable(value)));
      h_.origin = v;
    } else if (name == "axis mins") {
      double v[3];
      if (parse_numbers(value, v, 3)) h_.axis_mins = Vec3(v[0], v[1], v[2]);
    } else if (name == "endian") {
      const std::string e = lowercase(value);
      if (e != "little" && e != "big")
        fail_field(name, fmt::format("'{}' is neither little nor big", io::printable(value)));
      h_.big_endian = e == "big";
    } else if (name == "encoding") {
      const std::string e = lowercase(value);
      if (e == "raw")
        h_.encoding = Encoding::raw;
      else if (e == "gzip" || e == "gz")
        h_.encoding = Encoding::gzip;
      else if (e == "ascii" || e == "text" || e == "txt")
        h_.encoding = Encoding::ascii;
      else
        fail_field(name,
                   fmt::format("unsupported encoding '{}' (isohex reads raw, gzip and ascii)", io::printable(value)));
      h_.has_encoding = true;
    } else if (name == "line skip" || name == "lineskip") {
      if (!io::parse_int(value, h_.line_skip) || h_.line_skip < 0)
        fail_field(name, fmt::format("'{}' is not a non-negative integer", io::printable(value)));
    } else if (name == "byte skip" || name == "byteskip") {
      if (!io::parse_int(value, h_.byte_skip) || h_.byte_skip < -1)
        fail_field(name, fmt::format("'{}' is not an integer >= -1", io::printable(value)));
    } else if (name == "data file" || name == "datafile") {
      data_file(value, tokens);
    } else if (name == "block size" || name == "blocksize") {
      fail_field(name, "type 'block' is not supported");
    }
    // Other fields (content, kinds, centers, labels, units, space, ...) do not change the values.
  }

  void data_file(std::string_view value, const std::vector<std::string_view>& tokens) {
    data_file_seen_ = true;
    if (!tokens.empty() && lowercase(tokens[0]) == "list") {
      list_ = true;
      return;
    }
    if (tokens.size() >= 4 && tokens[0].find('%') != std::string_view::npos) {
      std::int64_t lo = 0, hi = 0, step = 0;
      if (!io::parse_int(tokens[1], lo) || !io::parse_int(tokens[2], hi) || !io::parse_int(tokens[3], step) ||
          step == 0)
        fail_field("data file", "a numbered series needs integer min, max and a non-zero step");
      if ((hi - lo) / step < 0 || (hi - lo) / step > 1000000)
        fail_field("data file", fmt::format("the series {} to {} by {} is empty or too long", lo, hi, step));
      for (std::int64_t n = lo; step > 0 ? n <= hi : n >= hi; n += step) {
        const auto name = format_series_name(tokens[0], n);
        if (!name)
          fail_field("data file", fmt::format("'{}' is not a name pattern with one %d", io::printable(tokens[0])));
        h_.data_files.push_back(resolve(*name));
      }
      return;
    }
    h_.data_files.push_back(resolve(value));
  }

  void check() {
    if (!dimension_seen_) fail_field("dimension", "is missing");
    if (!h_.type) fail_field("type", "is missing");
    if (!h_.sizes) fail_field("sizes", "is missing");
    if (!h_.has_encoding) fail_field("encoding", "is missing");
    if (!h_.big_endian && scalar_type_size(*h_.type) > 1 && h_.encoding != Encoding::ascii)
      fail_field("endian", fmt::format("is missing (needed for {} data)", nrrd_type_name(*h_.type)));
    if (h_.byte_skip == -1 && h_.encoding != Encoding::raw)
      fail_field("byte skip", "-1 (data at the end of the file) is only allowed with raw encoding");
  }

  const fs::path& file_;
  std::string_view text_;
  bool whole_;
  NrrdHeader h_;
  bool list_ = false, data_file_seen_ = false, dimension_seen_ = false;
};

/// Skips `lines` newline-terminated lines of `src`.
void skip_lines(ByteSource& src, std::int64_t lines, const fs::path& file) {
  unsigned char c;
  for (std::int64_t i = 0; i < lines; ++i) do {
      if (src.read(&c, 1) != 1)
        fail(file, "field 'line skip'", fmt::format("the data file has fewer than {} lines", lines));
    } while (c != '\n');
}

/// Reports a missing data file, or raw data shorter than the sizes need, before the
/// volume is allocated.
void check_data_files(const NrrdHeader& h, const fs::path& header_file, std::size_t count) {
  for (const fs::path& f : h.data_files)
    if (!fs::exists(f)) fail(header_file, "field 'data file'", fmt::format("data file {} does not exist", f.string()));
  if (h.encoding != Encoding::raw || h.byte_skip < 0 || h.line_skip != 0) return;
  const std::vector<fs::path> files = h.data_files.empty() ? std::vector<fs::path>{header_file} : h.data_files;
  const std::size_t per_file = count * scalar_type_size(*h.type) / files.size();
  for (const fs::path& f : files) {
    const std::size_t start = (h.data_files.empty() ? h.data_offset : 0) + static_cast<std::size_t>(h.byte_skip);
    const std::size_t size = size_of_file(f);
    if (size < start + per_file)
      fail(f, "data",
           fmt::format("has {} bytes of data after byte {}, but sizes {} x {} x {} of type {} need {}{} "
                       "(truncated, or the header lies)",
                       size > start ? size - start : 0, start, (*h.sizes)[0], (*h.sizes)[1], (*h.sizes)[2],
                       nrrd_type_name(*h.type), per_file, files.size() > 1 ? " per file" : ""));
  }
}

void read_binary(const NrrdHeader& h, const fs::path& header_file, Volume& v) {
  const bool big = h.big_endian.value_or(false);
  const ScalarType type = *h.type;
  const std::vector<fs::path> files = h.data_files.empty() ? std::vector<fs::path>{header_file} : h.data_files;
  const std::size_t total = v.size() * scalar_type_size(type);
  if (total % files.size() != 0)
    fail(header_file, "field 'data file'",
         fmt::format("{} data files cannot share {} bytes of data evenly", files.size(), total));
  const std::size_t per_file = total / files.size();
  // One stream over all files, each opened as it is reached, with its skips applied.
  class Series final : public ByteSource {
   public:
    Series(const NrrdHeader& h, const std::vector<fs::path>& files, std::size_t per_file)
        : h_(h), files_(files), per_file_(per_file) {}
    std::size_t read(unsigned char* out, std::size_t n) override {
      std::size_t done = 0;
      while (done < n) {
        if (left_ == 0 && !open_next()) break;
        const std::size_t got = read_full(*stream_, out + done, std::min(n - done, left_));
        if (got == 0)
          fail(files_[index_ - 1], "data",
               fmt::format("ends {} bytes short of the {} bytes this file should hold", left_, per_file_));
        done += got;
        left_ -= got;
      }
      return done;
    }

   private:
    bool open_next() {
      if (index_ == files_.size()) return false;
      const fs::path& f = files_[index_++];
      const bool attached = h_.data_files.empty();
      std::size_t offset = attached ? h_.data_offset : 0;
      if (h_.byte_skip == -1) {
        const std::size_t size = size_of_file(f);
        if (size < per_file_ + offset)
          fail(f, "field 'byte skip'",
               fmt::format("-1 needs {} bytes of data at the end, but the file has only {}", per_file_, size));
        offset = size - per_file_;
      }
      stream_ = nullptr;
      inflate_.reset();
      file_ = std::make_unique<FileSource>(f, offset);
      if (h_.byte_skip != -1) skip_lines(*file_, h_.line_skip, f);
      ByteSource* src = file_.get();
      if (h_.encoding == Encoding::gzip) {
        inflate_ = std::make_unique<InflateSource>(*file_, f, "gzip data");
        src = inflate_.get();
      }
      if (h_.byte_skip > 0 && !src->skip(static_cast<std::size_t>(h_.byte_skip)))
        fail(f, "field 'byte skip'", fmt::format("the data is shorter than the {} bytes to skip", h_.byte_skip));
      stream_ = src;
      left_ = per_file_;
      return true;
    }
    const NrrdHeader& h_;
    const std::vector<fs::path>& files_;
    std::size_t per_file_, index_ = 0, left_ = 0;
    std::unique_ptr<FileSource> file_;
    std::unique_ptr<InflateSource> inflate_;
    ByteSource* stream_ = nullptr;
  };
  Series series(h, files, per_file);
  read_samples(series, type, big, v, files.front(), "data");
}

void read_ascii(const NrrdHeader& h, const fs::path& header_file, Volume& v) {
  if (h.data_files.size() > 1) fail(header_file, "field 'data file'", "ascii data must be in one file");
  const fs::path file = h.data_files.empty() ? header_file : h.data_files.front();
  const std::string text = io::read_file(file);
  std::size_t offset = h.data_files.empty() ? h.data_offset : 0;
  for (std::int64_t i = 0; i < h.line_skip; ++i) {
    offset = text.find('\n', offset);
    if (offset == std::string::npos) fail(file, "field 'line skip'", "the data file has too few lines");
    ++offset;
  }
  offset += static_cast<std::size_t>(std::max<std::int64_t>(0, h.byte_skip));
  io::TextScanner scanner(text, file, offset);
  read_ascii_samples(scanner, v, "ascii data");
}

}  // namespace

Volume read_nrrd(const fs::path& file, const VolumeReadOptions& options) {
  const NrrdHeader h =
      parse_header(file, [&](std::string_view text, bool whole) { return HeaderParser(file, text, whole).run(); });
  const std::size_t count = check_dims(file, "field 'sizes'", *h.sizes, options);
  if (h.encoding != Encoding::ascii) check_data_files(h, file, count);
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  if (h.directions) {
    axes = *h.directions;
  } else if (h.spacings) {
    check_vector(file, "field 'spacings'", *h.spacings, true);
    axes = h.spacings->asDiagonal();
  }
  const Vec3 origin = h.origin ? *h.origin : h.axis_mins.value_or(Vec3::Zero());
  Volume v = allocate_volume(file, "field 'sizes'", *h.sizes, *h.type, options);
  if (h.encoding == Encoding::ascii)
    read_ascii(h, file, v);
  else
    read_binary(h, file, v);
  place_grid(v, axes, origin, file, h.directions ? "field 'space directions'" : "field 'space origin'");
  return v;
}

void write_nrrd(const fs::path& file, const Volume& volume) {
  const ScalarType type = storage_type(volume);
  io::write_atomically(file, [&](std::ostream& os) {
    std::string head = fmt::format(
        "NRRD0004\n# Complete NRRD file format specification at:\n# http://teem.sourceforge.net/nrrd/format.html\n"
        "# written by isohex\ntype: {}\ndimension: 3\nspace dimension: 3\nsizes: {} {} {}\n"
        "space directions: ({:.17g},0,0) (0,{:.17g},0) (0,0,{:.17g})\nkinds: domain domain domain\n",
        nrrd_type_name(type), volume.dims[0], volume.dims[1], volume.dims[2], volume.spacing.x(), volume.spacing.y(),
        volume.spacing.z());
    if (scalar_type_size(type) > 1) head += "endian: little\n";
    head += fmt::format("encoding: raw\nspace origin: ({:.17g},{:.17g},{:.17g})\n\n", volume.origin.x(),
                        volume.origin.y(), volume.origin.z());
    os << head;
    write_samples_le(os, volume, type);
  });
}

}  // namespace isohex::volume_detail
