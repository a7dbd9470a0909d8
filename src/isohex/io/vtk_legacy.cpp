// Legacy VTK UNSTRUCTURED_GRID reader, ASCII and BINARY (big-endian), both cell layouts:
// "CELLS n size" with "npts id..." records (versions 2.0-4.2) and "CELLS n+1 m" followed by
// OFFSETS / CONNECTIVITY arrays (5.1). The writer is in vtk_legacy_write.cpp.
//
// Binary data start on the line after their header line (VTK reads the header's newline,
// then raw bytes), so binary arrays are located by consuming the rest of the header line.
// Errors name a line in ASCII files and a byte offset in binary ones.

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/format_support.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/io/text_scanner.hpp"
#include "isohex/io/vtk_legacy_types.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace isohex::io {

namespace {

namespace fs = std::filesystem;

constexpr std::uint64_t kMaxIndex = static_cast<std::uint64_t>(std::numeric_limits<Index>::max());
constexpr std::uint64_t kMaxCount = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

bool is_block_array_name(std::string_view name) {
  for (std::string_view known : {"block", "BlockId", "CellEntityIds", "gmsh:physical", "MaterialIds"})
    if (iequals(name, known)) return true;
  return false;
}

/// One pass over a legacy file held in memory.
class LegacyReader {
 public:
  LegacyReader(std::string_view text, const fs::path& file, const ReadOptions& options)
      : text_(text), sc_(text, file), options_(options) {}

  HexMesh read(ReadReport& report) {
    read_header();
    while (sc_.skip_space()) read_keyword();
    return assemble(report);
  }

 private:
  enum class Section { geometry, point_data, cell_data };

  // ---- places and failures -----------------------------------------------------------

  /// "line N" in ASCII files (the scanner's line), "byte N" in binary ones.
  [[nodiscard]] std::string place(std::size_t offset) const {
    return binary_ ? fmt::format("byte {}", offset) : fmt::format("line {}", sc_.line());
  }
  [[noreturn]] void fail_at(std::size_t offset, std::string_view what) const {
    parse_error(sc_.file(), place(offset), what);
  }
  [[noreturn]] void fail(std::string_view what) const { fail_at(sc_.offset(), what); }
  /// The place of value i of the array being read.
  [[nodiscard]] std::string value_place(std::uint64_t i) const {
    return place(data_start_ + (value_bits_ == 1 ? i / 8 : i * value_size_));
  }
  [[noreturn]] void fail_value(std::uint64_t i, std::string_view what) const {
    parse_error(sc_.file(), value_place(i), what);
  }

  // ---- header tokens -----------------------------------------------------------------

  std::string_view token(std::string_view what) {
    const std::string_view t = sc_.next();
    if (t.empty()) fail(fmt::format("unexpected end of file, expected {}", what));
    token_start_ = sc_.offset() - t.size();
    return t;
  }

  std::uint64_t count(std::string_view what, std::uint64_t max) {
    const std::string_view t = token(what);
    std::int64_t v = 0;
    if (!parse_int(t, v) || v < 0)
      fail_at(token_start_, fmt::format("expected {} (a non-negative integer), found '{}'", what, printable(t)));
    if (static_cast<std::uint64_t>(v) > max)
      fail_at(token_start_, fmt::format("{} {} exceeds the limit of {}", what, v, max));
    return static_cast<std::uint64_t>(v);
  }

  vtk::Scalar data_type(std::string_view what) {
    const std::string_view t = token(what);
    const auto s = vtk::scalar_named(t);
    if (!s) fail_at(token_start_, fmt::format("unknown data type '{}' for {}", printable(t), what));
    type_name_ = t;
    return *s;
  }

  void expect_keyword(std::string_view keyword) {
    const std::string_view t = token(keyword);
    if (!iequals(t, keyword)) fail_at(token_start_, fmt::format("expected {}, found '{}'", keyword, printable(t)));
  }

  /// True if the next token (past whitespace) is `keyword`; consumes nothing.
  [[nodiscard]] bool peek_keyword(std::string_view keyword) const {
    std::size_t p = sc_.offset();
    while (p < text_.size() && is_space(text_[p])) ++p;
    const std::string_view rest = text_.substr(p);
    return istarts_with(rest, keyword) && (rest.size() == keyword.size() || is_space(rest[keyword.size()]));
  }

  static std::uint64_t product(std::uint64_t a, std::uint64_t b) {
    return (a != 0 && b > kMaxCount / a) ? kMaxCount : a * b;  // saturates; check_room refuses it
  }

  // ---- arrays ------------------------------------------------------------------------

  /// Fails unless `n` values (of `size` bytes each in binary files, one token of at least
  /// two characters in ASCII ones) fit in what is left: huge declared counts are refused
  /// before anything is allocated.
  void check_room(std::uint64_t n, vtk::Scalar s, std::string_view what) const {
    const std::uint64_t left = text_.size() - sc_.offset();
    std::uint64_t fits = 0;
    if (!binary_ || s == vtk::Scalar::string)
      fits = (left + 1) / 2;
    else if (s == vtk::Scalar::bit)
      fits = left * 8;
    else
      fits = left / vtk::size_of(s);
    if (n > fits)
      fail(fmt::format("{} declares {} values, more than the {} bytes left in the file can hold", what, n, left));
  }

  /// Moves to the first byte of an array's data.
  void begin_data(vtk::Scalar s) {
    if (binary_) sc_.rest_of_line();
    data_start_ = sc_.offset();
    value_size_ = vtk::size_of(s);
    value_bits_ = s == vtk::Scalar::bit ? 1 : 0;
  }

  /// The next `bytes` bytes of binary data, moving past them.
  const unsigned char* take(std::uint64_t bytes, std::string_view what) {
    const std::uint64_t left = text_.size() - sc_.offset();
    if (bytes > left)
      fail(fmt::format("unexpected end of file in {}: {} bytes of data declared, {} left", what, bytes, left));
    const auto* p = reinterpret_cast<const unsigned char*>(text_.data() + sc_.offset());
    sc_.seek(sc_.offset() + bytes);
    return p;
  }

  std::string_view ascii_value(std::string_view what) {
    const std::string_view t = sc_.next();
    if (t.empty()) fail(fmt::format("unexpected end of file, expected {}", what));
    return t;
  }

  /// Reads n numbers of any numeric type as doubles; sink(i, value).
  template <class Sink>
  void read_reals(vtk::Scalar s, std::uint64_t n, std::string_view what, Sink&& sink) {
    if (s == vtk::Scalar::string) fail(fmt::format("{} must be numbers, not strings", what));
    check_room(n, s, what);
    begin_data(s);
    if (!binary_) {
      for (std::uint64_t i = 0; i < n; ++i) {
        const std::string_view t = ascii_value(what);
        double v = 0;
        if (!parse_double(t, v)) fail(fmt::format("expected {} (a finite number), found '{}'", what, printable(t)));
        sink(i, v);
      }
    } else if (s == vtk::Scalar::bit) {
      const unsigned char* p = take((n + 7) / 8, what);
      for (std::uint64_t i = 0; i < n; ++i) sink(i, static_cast<double>((p[i / 8] >> (7 - i % 8)) & 1));
    } else {
      const unsigned char* p = take(n * vtk::size_of(s), what);
      vtk::decode_binary(s, p, n, [&](std::uint64_t i, auto v) { sink(i, static_cast<double>(v)); });
    }
    skip_metadata();
  }

  /// Reads n integers (integer types only) exactly; sink(i, value).
  template <class Sink>
  void read_ints(vtk::Scalar s, std::uint64_t n, std::string_view what, Sink&& sink) {
    if (!vtk::is_integer(s)) fail(fmt::format("{} must have an integer type, not '{}'", what, printable(type_name_)));
    check_room(n, s, what);
    begin_data(s);
    if (!binary_) {
      for (std::uint64_t i = 0; i < n; ++i) {
        const std::string_view t = ascii_value(what);
        std::int64_t v = 0;
        if (!parse_int(t, v)) fail(fmt::format("expected {} (an integer), found '{}'", what, printable(t)));
        sink(i, v);
      }
    } else if (s == vtk::Scalar::bit) {
      const unsigned char* p = take((n + 7) / 8, what);
      for (std::uint64_t i = 0; i < n; ++i) sink(i, std::int64_t{(p[i / 8] >> (7 - i % 8)) & 1});
    } else {
      const unsigned char* p = take(n * vtk::size_of(s), what);
      vtk::decode_binary(s, p, n, [&](std::uint64_t i, auto v) {
        if constexpr (std::is_same_v<decltype(v), std::uint64_t>)
          if (v > kMaxCount) fail_value(i, fmt::format("{} {} is too large", what, v));
        sink(i, static_cast<std::int64_t>(v));
      });
    }
    skip_metadata();
  }

  /// Moves past n values of an array that is not needed.
  void skip_values(vtk::Scalar s, std::uint64_t n, std::string_view what) {
    check_room(n, s, what);
    begin_data(s);
    if (s == vtk::Scalar::string) {
      skip_strings(n, what);
    } else if (!binary_) {
      for (std::uint64_t i = 0; i < n; ++i) ascii_value(what);
    } else {
      take(s == vtk::Scalar::bit ? (n + 7) / 8 : n * vtk::size_of(s), what);
    }
    skip_metadata();
  }

  /// String arrays: one value per line in ASCII; in binary a big-endian length whose two top
  /// bits of the first byte say how wide it is (11: 6 bits, 10: 14, 01: 30, 00: 64), then bytes.
  void skip_strings(std::uint64_t n, std::string_view what) {
    if (!binary_) sc_.rest_of_line();
    for (std::uint64_t i = 0; i < n; ++i) {
      if (sc_.at_end()) fail(fmt::format("unexpected end of file in {}: string {} of {} missing", what, i, n));
      if (!binary_) {
        sc_.rest_of_line();
        continue;
      }
      const auto first = static_cast<unsigned char>(text_[sc_.offset()]);
      const int width = (first >> 6) == 3 ? 1 : (first >> 6) == 2 ? 2 : (first >> 6) == 1 ? 4 : 8;
      const unsigned char* p = take(static_cast<std::uint64_t>(width), what);
      std::uint64_t length = 0;
      for (int b = 0; b < width; ++b) length = (length << 8) | p[b];
      if (width < 8) length &= (std::uint64_t{1} << (8 * width - 2)) - 1;
      take(length, what);
    }
  }

  /// 5.1 files may follow an array with "METADATA" and lines up to a blank one.
  void skip_metadata() {
    if (!peek_keyword("METADATA")) return;
    sc_.next();
    sc_.rest_of_line();
    while (!sc_.at_end()) {
      const std::string_view line = sc_.rest_of_line();
      if (line.find_first_not_of(" \t\r\f\v") == std::string_view::npos) break;
    }
  }

  // ---- sections ----------------------------------------------------------------------

  void read_header() {
    constexpr std::string_view kMagic = "# vtk DataFile Version";
    const std::string_view first = sc_.rest_of_line();
    if (first.substr(0, kMagic.size()) != kMagic)
      fail_at(0, fmt::format("not a legacy VTK file: the first line must start with '{}'", kMagic));
    std::string_view version = first.substr(kMagic.size());
    const auto begin = version.find_first_not_of(" \t");
    version = begin == std::string_view::npos ? std::string_view{} : version.substr(begin);
    version = version.substr(0, version.find_first_of(" \t"));
    version_ = version.empty() ? "(no version)" : printable(version);
    if (sc_.at_end()) fail("unexpected end of file, expected the title line");
    sc_.rest_of_line();  // the title
    const std::string_view mode = token("ASCII or BINARY");
    if (iequals(mode, "BINARY"))
      binary_ = true;
    else if (!iequals(mode, "ASCII"))
      fail_at(token_start_, fmt::format("expected ASCII or BINARY, found '{}'", printable(mode)));
    expect_keyword("DATASET");
    const std::string_view type = token("the dataset type");
    if (!iequals(type, "UNSTRUCTURED_GRID"))
      fail_at(token_start_,
              fmt::format("dataset type '{}' is not supported (only UNSTRUCTURED_GRID)", printable(type)));
  }

  void read_keyword() {
    const std::string_view kw = token("a keyword");
    const std::size_t at = token_start_;
    if (iequals(kw, "POINTS"))
      read_points();
    else if (iequals(kw, "CELLS"))
      read_cells();
    else if (iequals(kw, "CELL_TYPES"))
      read_cell_types();
    else if (iequals(kw, "POINT_DATA") || iequals(kw, "CELL_DATA"))
      begin_attributes(iequals(kw, "POINT_DATA") ? Section::point_data : Section::cell_data);
    else if (iequals(kw, "FIELD"))
      read_field();
    else if (iequals(kw, "METADATA"))
      fail_at(at, "METADATA that does not follow an array");
    else if (section_ != Section::geometry && read_attribute(kw))
      return;
    else
      fail_at(at, fmt::format("unknown keyword '{}'", printable(kw)));
  }

  void read_points() {
    if (have_points_) fail_at(token_start_, "a second POINTS section");
    const std::uint64_t n = count("the number of points", kMaxIndex);
    const vtk::Scalar s = data_type("POINTS");
    if (s == vtk::Scalar::string) fail_at(token_start_, "POINTS must be numbers, not strings");
    check_room(3 * n, s, "POINTS");
    points_.resize(n);
    read_reals(s, 3 * n, "point coordinate", [&](std::uint64_t i, double v) {
      if (!std::isfinite(v)) fail_value(i, fmt::format("point {} has a non-finite coordinate ({})", i / 3, v));
      points_[i / 3][static_cast<Eigen::Index>(i % 3)] = v;
    });
    have_points_ = true;
  }

  void read_cells() {
    if (!have_points_) fail_at(token_start_, "CELLS before POINTS (the points must come first)");
    if (have_cells_) fail_at(token_start_, "a second CELLS section");
    const std::uint64_t a = count("the CELLS count", kMaxCount);
    const std::uint64_t b = count("the CELLS size", kMaxCount);
    if (peek_keyword("OFFSETS"))
      read_offsets_and_connectivity(a, b);
    else
      read_cell_records(a, b);
    have_cells_ = true;
  }

  void check_vertex_id(std::int64_t id, std::uint64_t cell, std::uint64_t value) const {
    if (id < 0 || static_cast<std::size_t>(id) >= points_.size())
      fail_value(value, fmt::format("cell {} has vertex id {} out of range [0, {}]", cell, id,
                                    static_cast<std::int64_t>(points_.size()) - 1));
  }

  /// Versions up to 4.2: `size` ints holding "npts id0 id1 ..." per cell.
  void read_cell_records(std::uint64_t ncells, std::uint64_t size) {
    if (ncells > kMaxIndex) fail_at(token_start_, fmt::format("{} cells exceed the limit of {}", ncells, kMaxIndex));
    if (size < ncells)
      fail_at(token_start_, fmt::format("CELLS size {} is smaller than the cell count {}", size, ncells));
    check_room(size, vtk::Scalar::i32, "CELLS");
    offsets_.assign(ncells + 1, 0);
    conn_.clear();
    conn_.reserve(size - ncells);
    begin_data(vtk::Scalar::i32);
    const unsigned char* p = binary_ ? take(size * 4, "CELLS") : nullptr;
    auto value = [&](std::uint64_t k) -> std::int64_t {
      if (p) return load_be<std::int32_t>(p + 4 * k);
      const std::string_view t = ascii_value("cell data");
      std::int64_t v = 0;
      if (!parse_int(t, v)) fail(fmt::format("expected cell data (an integer), found '{}'", printable(t)));
      return v;
    };
    std::uint64_t k = 0;
    for (std::uint64_t c = 0; c < ncells; ++c) {
      if (k >= size) fail_value(k, fmt::format("CELLS size {} is too small for {} cells", size, ncells));
      const std::int64_t npts = value(k++);
      if (npts < 0 || static_cast<std::uint64_t>(npts) > size - k)
        fail_value(k - 1, fmt::format("cell {} declares {} points, but only {} values of CELLS size {} are left", c,
                                      npts, size - k, size));
      for (std::int64_t j = 0; j < npts; ++j, ++k) {
        const std::int64_t id = value(k);
        check_vertex_id(id, c, k);
        conn_.push_back(static_cast<Index>(id));
      }
      offsets_[c + 1] = static_cast<std::int64_t>(conn_.size());
    }
    if (k != size) fail_value(k, fmt::format("CELLS size is {} but its {} cells hold {} values", size, ncells, k));
    skip_metadata();
  }

  /// Version 5.x: "CELLS n+1 m", then OFFSETS (n+1 values) and CONNECTIVITY (m values).
  void read_offsets_and_connectivity(std::uint64_t noffsets, std::uint64_t nconn) {
    const std::uint64_t ncells = noffsets == 0 ? 0 : noffsets - 1;
    if (ncells > kMaxIndex) fail_at(token_start_, fmt::format("{} cells exceed the limit of {}", ncells, kMaxIndex));
    if (noffsets == 0 && nconn != 0)
      fail_at(token_start_, fmt::format("CELLS declares no offsets but {} connectivity values", nconn));
    expect_keyword("OFFSETS");
    const vtk::Scalar so = data_type("OFFSETS");
    check_room(noffsets, so, "OFFSETS");
    offsets_.assign(ncells + 1, 0);
    read_ints(so, noffsets, "cell offset", [&](std::uint64_t i, std::int64_t v) {
      if (i == 0 && v != 0) fail_value(i, fmt::format("the first cell offset must be 0, found {}", v));
      if (i > 0 && v < offsets_[i - 1])
        fail_value(i, fmt::format("cell offset {} is {}, less than the previous offset {}", i, v, offsets_[i - 1]));
      if (static_cast<std::uint64_t>(v) > nconn)
        fail_value(i, fmt::format("cell offset {} is {}, beyond the {} connectivity values", i, v, nconn));
      if (i + 1 == noffsets && static_cast<std::uint64_t>(v) != nconn)
        fail_value(i, fmt::format("the last cell offset is {} but CELLS declares {} connectivity values", v, nconn));
      offsets_[i] = v;
    });
    expect_keyword("CONNECTIVITY");
    const vtk::Scalar sc = data_type("CONNECTIVITY");
    check_room(nconn, sc, "CONNECTIVITY");
    conn_.assign(nconn, 0);
    std::uint64_t cell = 0;
    read_ints(sc, nconn, "cell connectivity", [&](std::uint64_t i, std::int64_t id) {
      // The last offset equals nconn > i, so this stops at a real cell.
      while (static_cast<std::uint64_t>(offsets_[cell + 1]) <= i) ++cell;
      check_vertex_id(id, cell, i);
      conn_[i] = static_cast<Index>(id);
    });
  }

  void read_cell_types() {
    if (!have_cells_) fail_at(token_start_, "CELL_TYPES before CELLS");
    if (have_types_) fail_at(token_start_, "a second CELL_TYPES section");
    const std::uint64_t ncells = offsets_.size() - 1;
    const std::uint64_t n = count("the CELL_TYPES count", kMaxCount);
    if (n != ncells) fail_at(token_start_, fmt::format("CELL_TYPES has {} entries for {} cells", n, ncells));
    types_.assign(n, 0);
    type_name_ = "int";
    read_ints(vtk::Scalar::i32, n, "cell type", [&](std::uint64_t i, std::int64_t type) {
      const std::string_view name = vtk::cell_type_name(type);
      if (name.empty()) fail_value(i, fmt::format("cell {} has unknown VTK cell type {}", i, type));
      const std::int64_t npts = offsets_[i + 1] - offsets_[i];
      if (type == vtk::kHexahedron || type == vtk::kVoxel) {
        if (npts != 8)
          fail_value(i, fmt::format("cell {} is a {} (VTK type {}) with {} points instead of 8", i, name, type, npts));
      } else {
        note_non_hex(i, type);
      }
      types_[i] = static_cast<std::uint8_t>(type);
    });
    have_types_ = true;
  }

  void note_non_hex(std::uint64_t cell, std::int64_t type) {
    constexpr std::size_t kNamed = 8;
    if (non_hex_count_ == 0) non_hex_place_ = value_place(cell);
    if (non_hex_count_ < kNamed)
      non_hex_names_ +=
          fmt::format("{}cell {} ({}, VTK type {})", non_hex_count_ ? ", " : "", cell, vtk::cell_type_name(type), type);
    else if (non_hex_count_ == kNamed)
      non_hex_names_ += ", ...";
    ++non_hex_count_;
  }

  void begin_attributes(Section section) {
    const std::size_t at = token_start_;
    const std::uint64_t n =
        count(section == Section::point_data ? "the POINT_DATA count" : "the CELL_DATA count", kMaxCount);
    if (section == Section::point_data) {
      if (!have_points_) fail_at(at, "POINT_DATA before POINTS");
      if (n != points_.size()) fail_at(at, fmt::format("POINT_DATA has {} values for {} points", n, points_.size()));
    } else {
      if (!have_cells_) fail_at(at, "CELL_DATA before CELLS");
      if (n != offsets_.size() - 1)
        fail_at(at, fmt::format("CELL_DATA has {} values for {} cells", n, offsets_.size() - 1));
    }
    section_ = section;
    tuples_ = n;
  }

  /// SCALARS, VECTORS, ... of POINT_DATA / CELL_DATA; false if `kw` is none of them.
  bool read_attribute(std::string_view kw) {
    const vtk::Scalar reals = binary_ ? vtk::Scalar::u8 : vtk::Scalar::f32;  // colours and tables
    if (iequals(kw, "SCALARS")) {
      const std::string name = vtk::decode_name(token("the SCALARS name"));
      const vtk::Scalar s = data_type("SCALARS");
      const std::string type = std::string(type_name_);
      std::uint64_t ncomp = 1;
      if (!peek_keyword("LOOKUP_TABLE")) ncomp = count("the number of components", 1u << 20);
      expect_keyword("LOOKUP_TABLE");
      token("the lookup table name");
      type_name_ = type;
      data_array(name, s, ncomp, tuples_);
    } else if (iequals(kw, "COLOR_SCALARS")) {
      token("the COLOR_SCALARS name");
      skip_values(reals, product(tuples_, count("the number of colour components", 1u << 20)), "COLOR_SCALARS");
    } else if (iequals(kw, "LOOKUP_TABLE")) {
      token("the LOOKUP_TABLE name");
      skip_values(reals, product(4, count("the LOOKUP_TABLE size", kMaxCount)), "LOOKUP_TABLE");
    } else if (iequals(kw, "VECTORS") || iequals(kw, "NORMALS")) {
      skip_named_array(kw, 3);
    } else if (iequals(kw, "TENSORS")) {
      skip_named_array(kw, 9);
    } else if (iequals(kw, "TENSORS6")) {
      skip_named_array(kw, 6);
    } else if (iequals(kw, "GLOBAL_IDS") || iequals(kw, "PEDIGREE_IDS") || iequals(kw, "EDGE_FLAGS")) {
      skip_named_array(kw, 1);
    } else if (iequals(kw, "TEXTURE_COORDINATES")) {
      token("the TEXTURE_COORDINATES name");
      const std::uint64_t dim = count("the texture dimension", 3);
      skip_values(data_type("TEXTURE_COORDINATES"), product(tuples_, dim), "TEXTURE_COORDINATES");
    } else {
      return false;
    }
    return true;
  }

  void skip_named_array(std::string_view kw, std::uint64_t ncomp) {
    token("the array name");
    skip_values(data_type(kw), product(tuples_, ncomp), kw);
  }

  /// "FIELD name n" then n arrays "name ncomp ntuples type" + data.
  void read_field() {
    token("the FIELD name");
    const std::uint64_t narrays = count("the number of FIELD arrays", kMaxCount);
    for (std::uint64_t a = 0; a < narrays; ++a) {
      const std::string_view raw = token("a FIELD array name");
      if (raw == "NULL_ARRAY") continue;
      const std::string name = vtk::decode_name(raw);
      const std::uint64_t ncomp = count("the number of components", kMaxCount);
      const std::uint64_t ntuples = count("the number of tuples", kMaxCount);
      const vtk::Scalar s = data_type("the FIELD array");
      data_array(name, s, ncomp, ntuples);
    }
  }

  /// An attribute array: `fixed` point flags and block ids are kept, the rest skipped.
  void data_array(const std::string& name, vtk::Scalar s, std::uint64_t ncomp, std::uint64_t ntuples) {
    const bool single = ncomp == 1 && ntuples == tuples_;
    if (section_ == Section::point_data && single && name == "fixed" && s != vtk::Scalar::string) {
      fixed_.assign(ntuples, 0);
      read_reals(s, ntuples, "fixed flag", [&](std::uint64_t i, double v) { fixed_[i] = v != 0 ? 1 : 0; });
    } else if (section_ == Section::cell_data && single && block_array_.empty() && is_block_array_name(name) &&
               s != vtk::Scalar::string) {
      block_array_ = name;
      blocks_.assign(ntuples, 0);
      read_reals(s, ntuples, "block id", [&](std::uint64_t i, double v) {
        if (v != std::floor(v) || v < std::numeric_limits<Index>::min() || v > std::numeric_limits<Index>::max())
          fail_value(i, fmt::format("cell {} has {} {}, not a 32-bit integer", i, name, v));
        blocks_[i] = static_cast<Index>(v);
      });
    } else {
      skip_values(s, product(ncomp, ntuples), name);
    }
  }

  HexMesh assemble(ReadReport& report) {
    if (!have_points_) fail("no POINTS section");
    if (!have_cells_) fail("no CELLS section");
    if (!have_types_) fail("no CELL_TYPES section");
    if (non_hex_count_ > 0 && !options_.skip_non_hex)
      parse_error(sc_.file(), non_hex_place_,
                  fmt::format("{} of {} cells are not hexahedra: {} (read with skip_non_hex to drop them)",
                              non_hex_count_, types_.size(), non_hex_names_));
    HexMesh mesh;
    mesh.points = std::move(points_);
    mesh.fixed = std::move(fixed_);
    mesh.hexes.reserve(types_.size() - non_hex_count_);
    if (!blocks_.empty()) mesh.blocks.reserve(types_.size() - non_hex_count_);
    for (std::size_t c = 0; c < types_.size(); ++c) {
      if (types_[c] != vtk::kHexahedron && types_[c] != vtk::kVoxel) continue;
      const Index* v = conn_.data() + offsets_[c];
      if (types_[c] == vtk::kHexahedron)
        mesh.hexes.push_back({v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]});
      else  // a voxel numbers its corners lexicographically: swap 2-3 and 6-7 for hex order
        mesh.hexes.push_back({v[0], v[1], v[3], v[2], v[4], v[5], v[7], v[6]});
      if (!blocks_.empty()) mesh.blocks.push_back(blocks_[c]);
    }
    report.format = fmt::format("VTK legacy {} {}", version_, binary_ ? "binary" : "ASCII");
    report.skipped_cells = non_hex_count_;
    return mesh;
  }

  std::string_view text_;
  TextScanner sc_;
  const ReadOptions& options_;
  bool binary_ = false;
  std::string version_;
  std::size_t token_start_ = 0;
  std::string_view type_name_;  // the last data type token, for messages
  std::size_t data_start_ = 0;  // the array being read: where its data start,
  std::size_t value_size_ = 0;  // the bytes of one value (binary),
  int value_bits_ = 0;          // 1 for bit arrays

  Section section_ = Section::geometry;
  std::uint64_t tuples_ = 0;  // values per array in the current POINT_DATA / CELL_DATA
  bool have_points_ = false, have_cells_ = false, have_types_ = false;
  std::vector<Vec3> points_;
  std::vector<std::int64_t> offsets_;  // cell c uses conn_[offsets_[c] .. offsets_[c + 1])
  std::vector<Index> conn_;
  std::vector<std::uint8_t> types_;
  std::vector<std::uint8_t> fixed_;
  std::vector<Index> blocks_;
  std::string block_array_;
  std::size_t non_hex_count_ = 0;
  std::string non_hex_place_, non_hex_names_;
};

}  // namespace

HexMesh read_vtk_legacy(const fs::path& file, const ReadOptions& options, ReadReport* report) {
  const std::string text = read_file(file);
  ReadReport local;
  LegacyReader reader(text, file, options);
  return reader.read(report ? *report : local);
}

}  // namespace isohex::io
