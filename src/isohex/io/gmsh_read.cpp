// Gmsh 4.1 (.msh) reader, ASCII or binary, for the hexahedra of a mesh.
//
// Reads $MeshFormat (only version 4.1: older and newer layouts differ in every section),
// $PhysicalNames, $Entities (for the physical group of each volume), $Nodes and $Elements;
// other sections are skipped up to their $End line. Points are ordered by node tag and hexes
// by element tag, which restores the orders the writer started from. A hex's block is the
// first physical tag of its volume entity (the entity tag when it has none), or the value in
// the physical name when every name is a block_name. Elements of lower dimension (boundary
// quads, lines, points) are ignored; other 3D elements are an error unless skip_non_hex.
//
// Errors name the line in ASCII files and the byte offset in binary data.

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/io/solver_sets.hpp"
#include "isohex/io/text_scanner.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <vector>

namespace isohex::io {

namespace {

namespace fs = std::filesystem;

/// Nodes per element for Gmsh's element types 1..19 (0: unknown).
constexpr int kNodesOfType[] = {0, 2, 3, 4, 4, 8, 6, 5, 3, 6, 9, 10, 27, 18, 14, 1, 8, 20, 15, 13};
constexpr int kHex8 = 5;
bool is_3d_type(int type) { return type == 4 || (type >= 5 && type <= 7) || (type >= 11 && type <= 14) || type >= 17; }

/// The numbers of one section, in either encoding.
class Source {
 public:
  virtual ~Source() = default;
  /// A count or a node/element tag (size_t in binary).
  virtual std::uint64_t size(std::string_view what) = 0;
  /// An entity tag, dimension, type or physical tag (int in binary).
  virtual int tag(std::string_view what) = 0;
  virtual double real(std::string_view what) = 0;
  [[noreturn]] virtual void fail(std::string_view what) const = 0;
  /// Bytes left, to refuse counts the file cannot hold.
  [[nodiscard]] virtual std::size_t remaining() const = 0;
  /// Fails unless `n` items of at least `min_bytes` each can still follow.
  void check_count(std::uint64_t n, std::size_t min_bytes, std::string_view what) const {
    if (n > remaining() / min_bytes)
      fail(fmt::format("{} {} is more than the rest of the file can hold", what, n));
  }
};

class TextSource final : public Source {
 public:
  explicit TextSource(TextScanner& s) : s_(s) {}
  std::uint64_t size(std::string_view what) override {
    return static_cast<std::uint64_t>(s_.next_int(what, 0, std::numeric_limits<std::int64_t>::max()));
  }
  int tag(std::string_view what) override { return static_cast<int>(s_.next_int(what, INT_MIN, INT_MAX)); }
  double real(std::string_view what) override { return s_.next_double(what); }
  [[noreturn]] void fail(std::string_view what) const override { s_.fail(what); }
  [[nodiscard]] std::size_t remaining() const override { return s_.remaining(); }

 private:
  TextScanner& s_;
};

/// Native little-endian binary data from `offset` on (the reader checks the byte order).
class BinarySource final : public Source {
 public:
  BinarySource(std::string_view text, const fs::path& file, std::size_t offset)
      : text_(text), file_(file), pos_(offset) {}
  std::uint64_t size(std::string_view what) override { return get<std::uint64_t>(what); }
  int tag(std::string_view what) override { return get<std::int32_t>(what); }
  double real(std::string_view what) override {
    const double v = get<double>(what);
    if (!std::isfinite(v)) fail(fmt::format("{} is not finite", what));
    return v;
  }
  [[noreturn]] void fail(std::string_view what) const override {
    parse_error(file_, fmt::format("byte offset {}", pos_), what);
  }
  [[nodiscard]] std::size_t remaining() const override { return text_.size() - pos_; }
  [[nodiscard]] std::size_t offset() const { return pos_; }

 private:
  template <class T>
  T get(std::string_view what) {
    if (remaining() < sizeof(T)) fail(fmt::format("unexpected end of file, expected {}", what));
    T v;
    std::memcpy(&v, text_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::string_view text_;
  const fs::path& file_;
  std::size_t pos_;
};

class GmshReader {
 public:
  GmshReader(std::string_view text, const fs::path& file, const ReadOptions& options)
      : text_(text), file_(file), options_(options), s_(text, file) {}

  HexMesh read(ReadReport& report) {
    bool format_seen = false;
    while (s_.skip_space()) {
      const std::string_view header = s_.rest_of_line();
      const std::string_view name = trim(header);
      if (!name.starts_with("$") || name.starts_with("$End"))
        fail_at(s_.line() - 1, fmt::format("expected a section such as $Nodes, found '{}'", shown(name)));
      const std::string section(name.substr(1));
      if (!format_seen && section != "MeshFormat")
        fail_at(s_.line() - 1, "the file does not start with $MeshFormat: not a Gmsh mesh");
      if (section == "MeshFormat") {
        read_format();
        format_seen = true;
      } else if (section == "PhysicalNames") {
        read_physical_names();
      } else if (section == "Entities") {
        with_source([&](Source& src) { read_entities(src); });
      } else if (section == "Nodes") {
        if (nodes_seen_) fail_at(s_.line() - 1, "a second $Nodes section");
        nodes_seen_ = true;
        with_source([&](Source& src) { read_nodes(src); });
      } else if (section == "Elements") {
        if (!nodes_seen_) fail_at(s_.line() - 1, "$Elements before $Nodes");
        if (elements_seen_) fail_at(s_.line() - 1, "a second $Elements section");
        elements_seen_ = true;
        with_source([&](Source& src) { read_elements(src); });
      } else {
        skip_section(section);
        continue;
      }
      expect_end(section);
    }
    if (!format_seen) s_.fail("empty file: not a Gmsh mesh");
    // Gmsh always writes both; a file without them is cut short.
    if (!nodes_seen_) s_.fail("the file has no $Nodes section (is it cut short?)");
    if (!elements_seen_) s_.fail("the file has no $Elements section (is it cut short?)");
    return assemble(report);
  }

 private:
  static std::string_view trim(std::string_view s) {
    const auto b = s.find_first_not_of(" \t\r");
    if (b == std::string_view::npos) return {};
    return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
  }
  static std::string shown(std::string_view t) {
    return t.size() > 40 ? std::string(t.substr(0, 40)) + "..." : std::string(t);
  }
  [[noreturn]] void fail_at(std::size_t line, std::string_view what) const {
    parse_error(file_, fmt::format("line {}", line), what);
  }

  /// Runs `parse` on the section's data in the file's encoding.
  template <class F>
  void with_source(F parse) {
    if (!binary_) {
      TextSource src(s_);
      parse(src);
      return;
    }
    BinarySource src(text_, file_, s_.offset());
    parse(src);
    s_.seek(src.offset());
  }

  void expect_end(const std::string& section) {
    const std::string want = "$End" + section;
    if (s_.next() != want) s_.fail(fmt::format("expected {} (is a count in the section wrong?)", want));
  }

  void skip_section(const std::string& section) {
    const std::string want = "\n$End" + section;
    const auto at = text_.find(want, s_.offset() == 0 ? 0 : s_.offset() - 1);
    if (at == std::string_view::npos) s_.fail(fmt::format("section ${} has no ${}", section, want.substr(2)));
    s_.seek(at + want.size());
  }

  void read_format() {
    const std::string_view version = s_.expect("the format version");
    if (version != "4.1")
      s_.fail(fmt::format("Gmsh format version {} is not supported; isohex reads version 4.1 "
                          "(gmsh IN -save -format msh41 -o OUT converts)",
                          shown(version)));
    const std::int64_t type = s_.next_int("the file type (0 ASCII, 1 binary)", 0, 1);
    const std::int64_t data_size = s_.next_int("the data size");
    if (data_size != 8) s_.fail(fmt::format("data size {} is not supported (only 8)", data_size));
    s_.rest_of_line();
    binary_ = type == 1;
    if (binary_) {
      BinarySource src(text_, file_, s_.offset());
      const int one = src.tag("the byte order mark");
      if (one != 1)
        src.fail(one == 0x01000000 ? "the binary data has the other byte order (big-endian), which is not supported"
                                   : "expected the binary integer 1 after the format line");
      s_.seek(src.offset());
    }
  }

  void read_physical_names() {
    const std::int64_t n = s_.next_int("the number of physical names", 0, static_cast<std::int64_t>(s_.remaining()));
    for (std::int64_t i = 0; i < n; ++i) {
      const int dim = static_cast<int>(s_.next_int("a physical dimension", 0, 3));
      const int tag = static_cast<int>(s_.next_int("a physical tag", INT_MIN, INT_MAX));
      std::string_view name = trim(s_.rest_of_line());
      if (name.size() >= 2 && name.front() == '"' && name.back() == '"') name = name.substr(1, name.size() - 2);
      if (dim == 3) physical_names_[tag] = std::string(name);
    }
  }

  void read_entities(Source& src) {
    std::uint64_t counts[4];
    for (auto& c : counts) {
      c = src.size("an entity count");
      src.check_count(c, 5, "the entity count");
    }
    for (int dim = 0; dim < 4; ++dim)
      for (std::uint64_t e = 0; e < counts[dim]; ++e) {
        const int tag = src.tag("an entity tag");
        for (int k = 0; k < (dim == 0 ? 3 : 6); ++k) src.real(dim == 0 ? "a point coordinate" : "a bounding box value");
        const std::uint64_t nphys = src.size("the number of physical tags");
        src.check_count(nphys, 1, "the number of physical tags");
        for (std::uint64_t p = 0; p < nphys; ++p) {
          const int phys = src.tag("a physical tag");
          if (dim == 3 && p == 0) volume_physical_[tag] = phys;
        }
        if (dim == 0) continue;
        const std::uint64_t nb = src.size("the number of bounding entities");
        src.check_count(nb, 1, "the number of bounding entities");
        for (std::uint64_t b = 0; b < nb; ++b) src.tag("a bounding entity tag");
      }
  }

  void read_nodes(Source& src) {
    const std::uint64_t blocks = src.size("the number of node blocks");
    const std::uint64_t total = src.size("the number of nodes");
    src.check_count(total, 2, "the number of nodes");
    src.size("the smallest node tag");
    src.size("the largest node tag");
    if (total >= static_cast<std::uint64_t>(std::numeric_limits<Index>::max())) src.fail("too many nodes for 32-bit indices");
    nodes_.reserve(nodes_.size() + total);
    for (std::uint64_t b = 0; b < blocks; ++b) {
      const int dim = src.tag("an entity dimension");
      src.tag("an entity tag");
      const int parametric = src.tag("the parametric flag");
      const std::uint64_t n = src.size("the number of nodes in the block");
      if (dim < 0 || dim > 3 || parametric < 0 || parametric > 1)
        src.fail(fmt::format("node block {} has entity dimension {} and parametric flag {}", b + 1, dim, parametric));
      src.check_count(n, 2, "the number of nodes in the block");
      if (nodes_.size() + n > total) src.fail(fmt::format("the node blocks hold more than the {} nodes declared", total));
      const std::size_t first = nodes_.size();
      for (std::uint64_t i = 0; i < n; ++i) nodes_.push_back({src.size("a node tag"), Vec3::Zero()});
      const int extra = parametric ? dim : 0;
      for (std::uint64_t i = 0; i < n; ++i) {
        Vec3& p = nodes_[first + i].second;
        for (int k = 0; k < 3; ++k) p[k] = src.real("a node coordinate");
        for (int k = 0; k < extra; ++k) src.real("a parametric coordinate");
      }
    }
    if (nodes_.size() != total) src.fail(fmt::format("the node blocks hold {} nodes, {} were declared", nodes_.size(), total));
    std::sort(nodes_.begin(), nodes_.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t i = 1; i < nodes_.size(); ++i)
      if (nodes_[i].first == nodes_[i - 1].first) src.fail(fmt::format("node {} is defined twice", nodes_[i].first));
  }

  /// The index of the node with tag `tag`.
  Index node_index(Source& src, std::uint64_t tag, std::uint64_t element) const {
    const auto it = std::lower_bound(nodes_.begin(), nodes_.end(), tag,
                                     [](const auto& n, std::uint64_t t) { return n.first < t; });
    if (it == nodes_.end() || it->first != tag)
      src.fail(fmt::format("element {} names node {}, which is not defined in $Nodes (before this line)", element, tag));
    return static_cast<Index>(it - nodes_.begin());
  }

  void read_elements(Source& src) {
    const std::uint64_t blocks = src.size("the number of element blocks");
    const std::uint64_t total = src.size("the number of elements");
    src.check_count(total, 2, "the number of elements");
    src.size("the smallest element tag");
    src.size("the largest element tag");
    std::uint64_t seen = 0;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      const int dim = src.tag("an entity dimension");
      const int entity = src.tag("an entity tag");
      const int type = src.tag("an element type");
      const std::uint64_t n = src.size("the number of elements in the block");
      if (type < 1 || type >= static_cast<int>(std::size(kNodesOfType)))
        src.fail(fmt::format("element type {} is not one isohex knows (1..19)", type));
      const int per = kNodesOfType[type];
      src.check_count(n, static_cast<std::size_t>(2 * (per + 1)), "the number of elements in the block");
      seen += n;
      if (seen > total) src.fail(fmt::format("the element blocks hold more than the {} elements declared", total));
      const bool hex = type == kHex8;
      if (!hex && is_3d_type(type)) {
        if (!options_.skip_non_hex)
          src.fail(fmt::format("element block {} (entity {} of dimension {}) has elements of type {}, not 8-node "
                               "hexahedra (type 5); read with skip_non_hex to drop them",
                               b + 1, entity, dim, type));
        skipped_ += n;
      }
      const Index set = hex ? set_of_entity(entity) : -1;
      for (std::uint64_t e = 0; e < n; ++e) {
        const std::uint64_t tag = src.size("an element tag");
        Hex h{};
        for (int k = 0; k < per; ++k) {
          const std::uint64_t node = src.size("a node tag");
          if (hex) h[static_cast<std::size_t>(k)] = node_index(src, node, tag);
        }
        if (!hex) continue;
        if (hexes_.size() >= static_cast<std::size_t>(std::numeric_limits<Index>::max()))
          src.fail("too many hexes for 32-bit indices");
        hexes_.push_back({tag, h, set});
      }
    }
    if (seen != total) src.fail(fmt::format("the element blocks hold {} elements, {} were declared", seen, total));
  }

  /// The block set of volume entity `entity`: its physical group, else the entity itself.
  Index set_of_entity(int entity) {
    const auto phys = volume_physical_.find(entity);
    const bool physical = phys != volume_physical_.end();
    const int id = physical ? phys->second : entity;
    const auto key = std::make_pair(physical, id);
    const auto found = sets_.find(key);
    if (found != sets_.end()) return found->second;
    const Index index = static_cast<Index>(set_ids_.size());
    sets_.emplace(key, index);
    set_ids_.push_back(id);
    const auto name = physical ? physical_names_.find(id) : physical_names_.end();
    set_names_.push_back(name == physical_names_.end() ? std::string() : name->second);
    return index;
  }

  HexMesh assemble(ReadReport& report) {
    HexMesh mesh;
    mesh.points.reserve(nodes_.size());
    for (const auto& n : nodes_) mesh.points.push_back(n.second);
    std::stable_sort(hexes_.begin(), hexes_.end(), [](const HexRecord& a, const HexRecord& b) { return a.tag < b.tag; });
    std::vector<Index> set_of_hex;
    for (std::size_t i = 0; i < hexes_.size(); ++i) {
      if (i > 0 && hexes_[i].tag == hexes_[i - 1].tag)
        throw Error(fmt::format("{}: element {} is defined twice", file_.string(), hexes_[i].tag));
      mesh.hexes.push_back(hexes_[i].nodes);
      set_of_hex.push_back(hexes_[i].set);
    }
    mesh.blocks = blocks_from_sets(set_names_, set_ids_, set_of_hex);
    report.format = binary_ ? "Gmsh 4.1 binary" : "Gmsh 4.1 ASCII";
    report.skipped_cells = skipped_;
    return mesh;
  }

  struct HexRecord {
    std::uint64_t tag;
    Hex nodes;
    Index set;
  };

  std::string_view text_;
  const fs::path& file_;
  const ReadOptions& options_;
  TextScanner s_;
  bool binary_ = false;
  bool nodes_seen_ = false, elements_seen_ = false;
  std::map<int, std::string> physical_names_;  // of dimension 3
  std::map<int, int> volume_physical_;         // volume entity -> its first physical tag
  std::vector<std::pair<std::uint64_t, Vec3>> nodes_;
  std::vector<HexRecord> hexes_;
  std::map<std::pair<bool, int>, Index> sets_;
  std::vector<Index> set_ids_;
  std::vector<std::string> set_names_;
  std::size_t skipped_ = 0;
};

}  // namespace

HexMesh read_gmsh(const fs::path& file, const ReadOptions& options, ReadReport* report) {
  const std::string text = read_file(file);
  ReadReport local;
  GmshReader reader(text, file, options);
  return reader.read(report ? *report : local);
}

}  // namespace isohex::io
