// Abaqus input (.inp) reader and writer, for the mesh part of the format.
//
// Lines starting with "**" are comments, lines starting with "*" are keywords with
// comma-separated parameters (case-insensitive), other lines are comma-separated data of
// the last keyword. Node and element ids are arbitrary positive integers: nodes get compact
// indices in file order; hexes are ordered by element id, so that a file whose elements are
// grouped by block (as the writer groups them) reads back in its original order.
// Blocks come from the ELSET of each *ELEMENT: "EB<n>" is block n when every set is named
// so, otherwise sets are numbered 1, 2, ... by first appearance. *NSET, NSET=FIXED lists
// the fixed vertices. Every other keyword is skipped with its data lines.
//
// The writer adds what a solver deck needs to refer to: *ELSET ALLHEXES, *NSET BOUNDARY
// (the boundary nodes) and *SURFACE BOUNDARY, the boundary quads as element faces S1..S6,
// and one *SURFACE per named face set of the mesh (a cut's surface)
// in Abaqus' C3D8 face numbering (solver_sets.hpp). Every field of its data lines fits in
// the 20 characters CalculiX reads a number from (abaqus.hpp), every line in the 256
// characters Abaqus allows.

#include "isohex/io/abaqus.hpp"

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/format_support.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/io/solver_sets.hpp"
#include "isohex/io/text_scanner.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

namespace isohex::io {

namespace {

namespace fs = std::filesystem;

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

/// Splits `line` at commas into trimmed fields (appended to `out`).
void split_fields(std::string_view line, std::vector<std::string_view>& out) {
  for (;;) {
    const auto comma = line.find(',');
    out.push_back(trim(line.substr(0, comma)));
    if (comma == std::string_view::npos) return;
    line.remove_prefix(comma + 1);
  }
}

/// C3D8 and its variants (C3D8R, C3D8I, C3D8H, C3D8RH, ...): letters after "C3D8".
bool is_hex_type(std::string_view type) {
  if (!istarts_with(type, "C3D8")) return false;
  return std::all_of(type.begin() + 4, type.end(),
                     [](char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); });
}

std::string upper(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
  return out;
}

/// Maps arbitrary integer ids to indices: a flat table while ids stay reasonably dense,
/// a hash map once one is far beyond the number of ids seen.
class IdIndex {
 public:
  /// Adds id -> index; returns false if id was already present.
  bool insert(std::int64_t id, Index index) {
    ++size_;
    if (!sparse_mode_ && id >= 0 && static_cast<std::uint64_t>(id) <= dense_limit()) {
      if (static_cast<std::size_t>(id) >= dense_.size())
        dense_.resize(std::max<std::size_t>(static_cast<std::size_t>(id) + 1, 2 * dense_.size()), -1);
      Index& slot = dense_[static_cast<std::size_t>(id)];
      if (slot >= 0) return false;
      slot = index;
      return true;
    }
    if (!sparse_mode_) to_sparse();
    return sparse_.emplace(id, index).second;
  }
  /// The index of id, or -1.
  [[nodiscard]] Index find(std::int64_t id) const {
    if (sparse_mode_) {
      const auto it = sparse_.find(id);
      return it == sparse_.end() ? -1 : it->second;
    }
    return id >= 0 && static_cast<std::size_t>(id) < dense_.size() ? dense_[static_cast<std::size_t>(id)] : -1;
  }

 private:
  [[nodiscard]] std::uint64_t dense_limit() const { return 8 * static_cast<std::uint64_t>(size_) + (1u << 20); }
  void to_sparse() {
    sparse_.reserve(size_);
    for (std::size_t id = 0; id < dense_.size(); ++id)
      if (dense_[id] >= 0) sparse_.emplace(static_cast<std::int64_t>(id), dense_[id]);
    dense_.clear();
    dense_.shrink_to_fit();
    sparse_mode_ = true;
  }
  bool sparse_mode_ = false;
  std::size_t size_ = 0;
  std::vector<Index> dense_;
  std::unordered_map<std::int64_t, Index> sparse_;
};

class AbaqusReader {
 public:
  AbaqusReader(std::string_view text, const fs::path& file, const ReadOptions& options)
      : text_(text), file_(file), options_(options) {}

  HexMesh read(ReadReport& report) {
    std::string_view line;
    while (next_line(line)) {
      const std::string_view t = trim(line);
      if (t.empty() || t.starts_with("**")) continue;
      if (t.front() == '*') {
        finish_record();
        read_keyword(t);
      } else {
        read_data(t);
      }
    }
    finish_record();
    return assemble(report);
  }

 private:
  enum class Mode { skip, node, hex, non_hex, fixed_set };

  [[noreturn]] void fail(std::string_view what, std::size_t line = 0) const {
    parse_error(file_, fmt::format("line {}", line ? line : line_), what);
  }

  bool next_line(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    const auto end = text_.find('\n', pos_);
    line = text_.substr(pos_, end == std::string_view::npos ? std::string_view::npos : end - pos_);
    pos_ = end == std::string_view::npos ? text_.size() : end + 1;
    ++line_;
    return true;
  }

  /// `field` as an integer; a failure names `line` (default: the current line).
  std::int64_t integer(std::string_view field, std::string_view what, std::size_t line = 0) const {
    std::int64_t v = 0;
    if (!parse_int(field, v)) fail(fmt::format("expected {} (an integer), found '{}'", what, printable(field)), line);
    return v;
  }

  double real(std::string_view field, std::string_view what) const {
    double v = 0;
    if (!parse_double(field, v)) fail(fmt::format("expected {} (a finite number), found '{}'", what, printable(field)));
    return v;
  }

  // ---- keywords ----------------------------------------------------------------------

  /// "*NAME, KEY=VALUE, FLAG, ..." (a line ending with a comma continues on the next one).
  void read_keyword(std::string_view t) {
    params_.clear();
    split_fields(t.substr(1), params_);
    while (!params_.empty() && params_.back().empty() && next_keyword_continuation()) {
    }
    const std::string_view name = params_.front();
    if (iequals(name, "NODE")) {
      mode_ = Mode::node;
    } else if (iequals(name, "ELEMENT")) {
      begin_elements();
    } else if (iequals(name, "NSET") && iequals(param("NSET"), "FIXED")) {
      if (!param("ELSET").empty()) fail("*NSET, NSET=FIXED built from an ELSET is not supported");
      mode_ = Mode::fixed_set;
      generate_ = has_flag("GENERATE");
    } else if (iequals(name, "INCLUDE")) {
      fail("*INCLUDE is not supported: put the included file's content in place");
    } else {
      mode_ = Mode::skip;
    }
  }

  /// Appends the next line's parameters to a keyword line that ended with a comma.
  bool next_keyword_continuation() {
    std::string_view line;
    const std::size_t saved_pos = pos_, saved_line = line_;
    if (!next_line(line) || trim(line).starts_with("*")) {
      pos_ = saved_pos;
      line_ = saved_line;
      params_.pop_back();
      return false;
    }
    params_.pop_back();
    split_fields(trim(line), params_);
    return true;
  }

  /// The value of parameter `key` of the current keyword, quotes removed; empty if absent.
  [[nodiscard]] std::string_view param(std::string_view key) const {
    for (std::size_t i = 1; i < params_.size(); ++i) {
      const std::string_view p = params_[i];
      const auto eq = p.find('=');
      if (eq == std::string_view::npos || !iequals(trim(p.substr(0, eq)), key)) continue;
      std::string_view v = trim(p.substr(eq + 1));
      if (v.size() >= 2 && v.front() == '"' && v.back() == '"') v = v.substr(1, v.size() - 2);
      return v;
    }
    return {};
  }

  [[nodiscard]] bool has_flag(std::string_view key) const {
    for (std::size_t i = 1; i < params_.size(); ++i)
      if (iequals(params_[i], key)) return true;
    return false;
  }

  void begin_elements() {
    element_type_ = param("TYPE");
    if (element_type_.empty()) fail("*ELEMENT without TYPE=");
    mode_ = is_hex_type(element_type_) ? Mode::hex : Mode::non_hex;
    const std::string_view elset = param("ELSET");
    elset_ = -1;
    if (elset.empty() || mode_ != Mode::hex) return;  // sets of skipped elements are no blocks
    const std::string name = upper(elset);
    const auto found = std::find(elset_names_.begin(), elset_names_.end(), name);
    elset_ = static_cast<std::int32_t>(found - elset_names_.begin());
    if (found == elset_names_.end()) elset_names_.push_back(name);
  }

  // ---- data lines --------------------------------------------------------------------

  void read_data(std::string_view t) {
    switch (mode_) {
      case Mode::skip:
        return;
      case Mode::node:
        return read_node(t);
      case Mode::fixed_set:
        return read_fixed(t);
      case Mode::hex:
      case Mode::non_hex:
        if (record_.empty()) record_line_ = line_;
        split_fields(t, record_);
        // A trailing comma continues the element on the next line.
        if (!record_.empty() && record_.back().empty())
          record_.pop_back();
        else
          finish_record();
        return;
    }
  }

  void read_node(std::string_view t) {
    fields_.clear();
    split_fields(t, fields_);
    if (fields_.size() > 1 && fields_.back().empty()) fields_.pop_back();
    const std::int64_t id = integer(fields_[0], "a node id");
    if (fields_.size() < 4) fail(fmt::format("node {} has {} coordinates, 3 are needed", id, fields_.size() - 1));
    if (id < 1) fail(fmt::format("node id {} is not positive", id));
    if (points_.size() >= static_cast<std::size_t>(std::numeric_limits<Index>::max()))
      fail("too many nodes for 32-bit indices");
    const Vec3 p(real(fields_[1], "a node x coordinate"), real(fields_[2], "a node y coordinate"),
                 real(fields_[3], "a node z coordinate"));
    if (!node_index_.insert(id, static_cast<Index>(points_.size()))) fail(fmt::format("node {} is defined twice", id));
    points_.push_back(p);
  }

  /// The index of the node named by `field`, which `owner` (at `line`) refers to.
  Index node(std::string_view field, std::string_view owner, std::size_t line) const {
    const std::int64_t id = integer(field, "a node id", line);
    const Index v = node_index_.find(id);
    if (v < 0) fail(fmt::format("{} names node {}, which is not defined (before this line)", owner, id), line);
    return v;
  }
  Index node_of_element(std::string_view field, std::int64_t element) const {
    const std::int64_t id = integer(field, "a node id", record_line_);
    const Index v = node_index_.find(id);
    if (v < 0)
      fail(fmt::format("element {} names node {}, which is not defined (before this line)", element, id), record_line_);
    return v;
  }

  void read_fixed(std::string_view t) {
    fields_.clear();
    split_fields(t, fields_);
    if (fields_.size() > 1 && fields_.back().empty()) fields_.pop_back();
    if (!generate_) {
      for (const std::string_view f : fields_) fixed_list_.push_back(node(f, "NSET FIXED", line_));
      return;
    }
    if (fields_.size() < 2 || fields_.size() > 3) fail("NSET FIXED, GENERATE needs 'first, last[, step]'");
    const std::int64_t first = integer(fields_[0], "the first node id");
    const std::int64_t last = integer(fields_[1], "the last node id");
    const std::int64_t step = fields_.size() == 3 ? integer(fields_[2], "the step") : 1;
    // first >= 1 keeps last - first from overflowing; the count bounds the loop.
    if (first < 1 || step < 1 || last < first || (last - first) / step >= static_cast<std::int64_t>(points_.size()))
      fail(fmt::format("NSET FIXED, GENERATE range {}, {}, {} is not a range of defined nodes", first, last, step));
    for (std::int64_t k = 0; k <= (last - first) / step; ++k) {
      const std::int64_t id = first + k * step;
      const Index v = node_index_.find(id);
      if (v < 0) fail(fmt::format("NSET FIXED names node {}, which is not defined (before this line)", id));
      fixed_list_.push_back(v);
    }
  }

  /// Handles the element collected in record_ (if any).
  void finish_record() {
    if (record_.empty()) return;
    const std::int64_t id = integer(record_[0], "an element id", record_line_);
    if (mode_ == Mode::non_hex) {
      if (!options_.skip_non_hex)
        fail(fmt::format(
                 "element {} has type {}, not a hexahedron (C3D8, C3D8R, ...); read with skip_non_hex to drop it", id,
                 element_type_),
             record_line_);
      ++skipped_;
      record_.clear();
      return;
    }
    if (record_.size() != 9)
      fail(fmt::format("element {} of type {} has {} node ids instead of 8", id, element_type_, record_.size() - 1),
           record_line_);
    if (hexes_.size() >= static_cast<std::size_t>(std::numeric_limits<Index>::max()))
      fail("too many elements for 32-bit indices", record_line_);
    Hex h;
    for (int i = 0; i < 8; ++i)
      h[static_cast<std::size_t>(i)] = node_of_element(record_[static_cast<std::size_t>(i) + 1], id);
    if (!element_index_.insert(id, static_cast<Index>(hexes_.size())))
      fail(fmt::format("element {} is defined twice", id), record_line_);
    hexes_.push_back(h);
    element_ids_.push_back(id);
    elsets_.push_back(elset_);
    record_.clear();
  }

  // ---- result ------------------------------------------------------------------------

  /// Block id per ELSET name: n for "EB<n>" when all names are so, else 1, 2, ...
  [[nodiscard]] std::vector<Index> block_ids() const {
    std::vector<Index> ids(elset_names_.size());
    for (std::size_t i = 0; i < elset_names_.size(); ++i) {
      std::int64_t n = 0;
      const std::string_view name = elset_names_[i];
      if (!name.starts_with("EB") || !parse_int(name.substr(2), n) || name.substr(2).starts_with("+") ||
          n < std::numeric_limits<Index>::min() || n > std::numeric_limits<Index>::max()) {
        std::iota(ids.begin(), ids.end(), 1);
        return ids;
      }
      ids[i] = static_cast<Index>(n);
    }
    return ids;
  }

  HexMesh assemble(ReadReport& report) {
    HexMesh mesh;
    mesh.points = std::move(points_);
    // Hexes in element id order.
    std::vector<std::size_t> order(hexes_.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    if (!std::is_sorted(element_ids_.begin(), element_ids_.end()))
      std::sort(order.begin(), order.end(),
                [&](std::size_t a, std::size_t b) { return element_ids_[a] < element_ids_[b]; });
    const std::vector<Index> ids = block_ids();
    mesh.hexes.reserve(hexes_.size());
    std::vector<Index> blocks;
    blocks.reserve(hexes_.size());
    bool any_block = false;
    for (const std::size_t h : order) {
      mesh.hexes.push_back(hexes_[h]);
      const Index b = elsets_[h] < 0 ? 0 : ids[static_cast<std::size_t>(elsets_[h])];
      blocks.push_back(b);
      any_block = any_block || b != 0;
    }
    if (any_block) mesh.blocks = std::move(blocks);
    if (!fixed_list_.empty()) {
      mesh.fixed.assign(mesh.points.size(), 0);
      for (const Index v : fixed_list_) mesh.fixed[static_cast<std::size_t>(v)] = 1;
    }
    report.format = "Abaqus input";
    report.skipped_cells = skipped_;
    return mesh;
  }

  std::string_view text_;
  const fs::path& file_;
  const ReadOptions& options_;
  std::size_t pos_ = 0, line_ = 0;
  Mode mode_ = Mode::skip;  // data before the first keyword (a heading) is skipped
  std::vector<std::string_view> params_, fields_, record_;
  std::size_t record_line_ = 0;
  std::string_view element_type_;
  std::int32_t elset_ = -1;
  bool generate_ = false;

  std::vector<Vec3> points_;
  IdIndex node_index_, element_index_;
  std::vector<Hex> hexes_;
  std::vector<std::int64_t> element_ids_;
  std::vector<std::int32_t> elsets_;
  std::vector<std::string> elset_names_;
  std::vector<Index> fixed_list_;
  std::size_t skipped_ = 0;
};

// ---- numbers that fit a field ----------------------------------------------------------

/// A number as the writer spells it, at most kAbaqusFieldWidth characters.
class Field {
 public:
  [[nodiscard]] std::string_view view() const { return {text_.data(), size_}; }
  template <class... Args>
  void set(fmt::format_string<Args...> format, Args&&... args) {
    const auto r = fmt::format_to_n(text_.data(), text_.size(), format, std::forward<Args>(args)...);
    size_ = std::min(r.size, text_.size());  // a double's %.17g has at most 24 characters
  }
  /// The same value in fewer characters: "0.x" -> ".x", "e-07" -> "e-7", "e+17" -> "e17",
  /// and no trailing zeros in an exponent form's digits.
  void shorten() {
    std::string s(view());
    const auto e = s.find('e');
    if (e == std::string::npos) {
      const std::size_t at = s.front() == '-' ? 1 : 0;
      if (s.compare(at, 2, "0.") == 0) s.erase(at, 1);
    } else {
      std::size_t end = e;
      while (s[end - 1] == '0') --end;
      if (s[end - 1] == '.') --end;
      s.erase(end, e - end);
      std::size_t digit = s.find('e') + 1;
      if (s[digit] == '+')
        s.erase(digit, 1);
      else if (s[digit] == '-')
        ++digit;
      while (digit + 1 < s.size() && s[digit] == '0') s.erase(digit, 1);
    }
    size_ = std::min(s.size(), text_.size());
    std::copy_n(s.begin(), size_, text_.begin());
  }
  /// True if the text fits a field and reads back finite.
  [[nodiscard]] bool fits_finite() const {
    double back = 0;
    return size_ <= kAbaqusFieldWidth && parse_double(view(), back);  // parse_double refuses an overflow
  }

 private:
  std::array<char, 40> text_{};
  std::size_t size_ = 0;
};

/// abaqus_real's spelling of x: for p = 17, 16, ... the p-digit rounding as %.{p}g, the same
/// shortened, then in exponent form shortened; the first that fits. Beyond %.17g's fixed
/// range (|x| >= 1e17) the exact integer digits come first, which fit up to 1e19 or 1e20.
Field real_field(double x) {
  Field f;
  f.set("{:.17g}", x);
  if (f.fits_finite()) return f;
  if (std::abs(x) >= 1e16) {  // above 2^53 every double is an integer
    f.set("{:.0f}", x);
    if (f.fits_finite()) return f;
  }
  for (int p = 17; p >= 1; --p) {
    f.set("{:.{}g}", x, p);
    if (f.fits_finite()) return f;
    f.shorten();
    if (f.fits_finite()) return f;
    f.set("{:.{}e}", x, p - 1);
    f.shorten();
    if (f.fits_finite()) return f;
  }
  throw std::logic_error(fmt::format("no {}-character spelling of {}", kAbaqusFieldWidth, x));  // p = 13 always fits
}

/// 1-based ids of `vertices`, 16 to a line: the most Abaqus allows on a set data line.
void write_id_lines(TextOut& text, const std::vector<Index>& vertices) {
  for (std::size_t i = 0; i < vertices.size(); ++i)
    text.print("{}{}{}", i % 16 == 0 ? "" : ", ", vertices[i] + 1,
               i % 16 == 15 || i + 1 == vertices.size() ? "\n" : "");
}

// CalculiX reads ids with the format i10: 1-based 32-bit indices have at most 10 digits.
static_assert(sizeof(Index) <= 4);

void write_inp(std::ostream& out, const HexMesh& mesh) {
  TextOut text(out);
  // A comment, not *HEADING: CalculiX refuses a second *HEADING, so a file with one could
  // not be included in a deck that has its own.
  text.print("** isohex hex mesh\n*NODE, NSET=ALLNODES\n");
  for (std::size_t v = 0; v < mesh.points.size(); ++v) {
    const Vec3& p = mesh.points[v];
    text.print("{}, {}, {}, {}\n", v + 1, real_field(p.x()).view(), real_field(p.y()).view(), real_field(p.z()).view());
  }
  // One *ELEMENT per block; element ids keep the hex order, which the reader restores.
  std::vector<std::size_t> order(mesh.hexes.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return mesh.block(static_cast<Index>(a)) < mesh.block(static_cast<Index>(b));
  });
  for (std::size_t i = 0; i < order.size(); ++i) {
    const std::size_t h = order[i];
    const Index block = mesh.block(static_cast<Index>(h));
    if (i == 0 || block != mesh.block(static_cast<Index>(order[i - 1])))
      text.print("*ELEMENT, TYPE=C3D8, ELSET=EB{}\n", block);
    const Hex& x = mesh.hexes[h];
    text.print("{}, {}, {}, {}, {}, {}, {}, {}, {}\n", h + 1, x[0] + 1, x[1] + 1, x[2] + 1, x[3] + 1, x[4] + 1,
               x[5] + 1, x[6] + 1, x[7] + 1);
  }
  // Sets for the solver: all hexes, the boundary nodes, the boundary as an element-based
  // surface (element, face label) and the fixed vertices.
  if (!mesh.hexes.empty()) text.print("*ELSET, ELSET=ALLHEXES, GENERATE\n1, {}, 1\n", mesh.hexes.size());
  const std::vector<Index> bnodes = boundary_nodes(mesh);
  if (!bnodes.empty()) {
    text.print("*NSET, NSET=BOUNDARY\n");
    write_id_lines(text, bnodes);
  }
  const std::vector<BoundaryFace> faces = boundary_faces(mesh);
  if (!faces.empty()) text.print("*SURFACE, NAME=BOUNDARY, TYPE=ELEMENT\n");
  for (const BoundaryFace& f : faces) text.print("{}, S{}\n", f.hex + 1, kAbaqusFaceOfVtkFace[f.face]);
  // Named face sets (a cut's surface): element-based surfaces of their own.
  for (const FaceSet& fs : mesh.face_sets) {
    if (fs.faces.empty()) continue;
    std::string name = fs.name;
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    text.print("*SURFACE, NAME={}, TYPE=ELEMENT\n", name);
    for (const auto& [h, f] : fs.faces) text.print("{}, S{}\n", h + 1, kAbaqusFaceOfVtkFace[static_cast<std::size_t>(f)]);
  }
  std::vector<Index> fixed;
  for (std::size_t v = 0; v < mesh.fixed.size(); ++v)
    if (mesh.fixed[v]) fixed.push_back(static_cast<Index>(v));
  if (!fixed.empty()) {
    text.print("*NSET, NSET=FIXED\n");
    write_id_lines(text, fixed);
  }
  text.flush();
}

}  // namespace

std::string abaqus_real(double x) { return std::string(real_field(x).view()); }

HexMesh read_abaqus(const fs::path& file, const ReadOptions& options, ReadReport* report) {
  const std::string text = read_file(file);
  ReadReport local;
  AbaqusReader reader(text, file, options);
  return reader.read(report ? *report : local);
}

void write_abaqus(const fs::path& file, const HexMesh& mesh, const WriteOptions&) {
  check_mesh_for_writing(file, mesh);
  write_atomically(file, [&](std::ostream& out) { write_inp(out, mesh); });
}

}  // namespace isohex::io
