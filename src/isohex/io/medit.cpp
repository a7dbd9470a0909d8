// MEDIT / GMF ASCII (.mesh) reader and writer.
//
// The file is a sequence of keywords (case-insensitive), each followed by its values as
// whitespace-separated tokens; line breaks carry no meaning, '#' starts a comment. Sections
// this reader does not use are skipped by their known number of values per entry; an
// unknown keyword is an error, since its size cannot be known.
//
// Vertex references: the writer marks fixed vertices with reference 1 and the others 0.
// The reader takes references as fixed flags only when every reference is 0 or 1 (other
// tools use them as arbitrary surface labels, e.g. -1 everywhere in the ECR data), and
// also honours RequiredVertices, GMF's own "do not move" list. Hexahedron references are
// block ids.

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/format_support.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/io/text_scanner.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace isohex::io {

namespace {

namespace fs = std::filesystem;

constexpr std::int64_t kMaxIndex = std::numeric_limits<Index>::max();

enum class Kind { version, dimension, vertices, hexahedra, required_vertices, non_hex, skip, single, solution, end };

struct Keyword {
  std::string_view name;
  Kind kind;
  int values;  ///< values per entry (for `single`: values, no count)
};

// Entry sizes as in GMF (libMeshb's keyword table), "dr" being 3 reals in 3D.
constexpr Keyword kKeywords[] = {
    {"MeshVersionFormatted", Kind::version, 1},
    {"Dimension", Kind::dimension, 1},
    {"Vertices", Kind::vertices, 4},
    {"Hexahedra", Kind::hexahedra, 9},
    {"RequiredVertices", Kind::required_vertices, 1},
    {"Tetrahedra", Kind::non_hex, 5},
    {"Prisms", Kind::non_hex, 7},
    {"Pyramids", Kind::non_hex, 6},
    {"TetrahedraP2", Kind::non_hex, 11},
    {"HexahedraQ2", Kind::non_hex, 28},
    {"Edges", Kind::skip, 3},
    {"Triangles", Kind::skip, 4},
    {"Quadrilaterals", Kind::skip, 5},
    {"EdgesP2", Kind::skip, 4},
    {"TrianglesP2", Kind::skip, 7},
    {"QuadrilateralsQ2", Kind::skip, 10},
    {"Corners", Kind::skip, 1},
    {"Ridges", Kind::skip, 1},
    {"RequiredEdges", Kind::skip, 1},
    {"RequiredTriangles", Kind::skip, 1},
    {"RequiredQuadrilaterals", Kind::skip, 1},
    {"TangentAtEdgeVertices", Kind::skip, 3},
    {"NormalAtVertices", Kind::skip, 2},
    {"NormalAtTriangleVertices", Kind::skip, 3},
    // MEDIT's manual and most writers: quad, corner, normal (libMeshb's table lists 4 ints).
    {"NormalAtQuadrilateralVertices", Kind::skip, 3},
    {"TangentAtVertices", Kind::skip, 2},
    {"Normals", Kind::skip, 3},
    {"Tangents", Kind::skip, 3},
    {"VerticesOnGeometricVertices", Kind::skip, 2},
    {"VerticesOnGeometricEdges", Kind::skip, 4},
    {"VerticesOnGeometricTriangles", Kind::skip, 5},
    {"VerticesOnGeometricQuadrilaterals", Kind::skip, 5},
    {"EdgesOnGeometricEdges", Kind::skip, 2},
    {"TrianglesOnGeometricTriangles", Kind::skip, 2},
    {"TrianglesOnGeometricQuadrilaterals", Kind::skip, 2},
    {"QuadrilateralsOnGeometricTriangles", Kind::skip, 2},
    {"QuadrilateralsOnGeometricQuadrilaterals", Kind::skip, 2},
    {"AngleOfCornerBound", Kind::single, 1},
    {"Iterations", Kind::single, 1},
    {"Time", Kind::single, 1},
    {"SolAtVertices", Kind::solution, 0},
    {"SolAtEdges", Kind::solution, 0},
    {"SolAtTriangles", Kind::solution, 0},
    {"SolAtQuadrilaterals", Kind::solution, 0},
    {"SolAtTetrahedra", Kind::solution, 0},
    {"SolAtPrisms", Kind::solution, 0},
    {"SolAtHexahedra", Kind::solution, 0},
    {"SolAtPyramids", Kind::solution, 0},
    {"End", Kind::end, 0},
};

const Keyword* find_keyword(std::string_view name) {
  for (const Keyword& k : kKeywords)
    if (iequals(name, k.name)) return &k;
  return nullptr;
}

class MeditReader {
 public:
  MeditReader(std::string_view text, const fs::path& file, const ReadOptions& options)
      : sc_(text, file), options_(options), text_size_(text.size()) {}

  HexMesh read(ReadReport& report) {
    bool ended = false;
    while (!ended) {
      const std::string_view word = token();
      if (word.empty()) sc_.fail("unexpected end of file: no End keyword (is the file truncated?)");
      const Keyword* k = find_keyword(word);
      if (!k) sc_.fail(fmt::format("unknown keyword '{}'", printable(word)));
      ended = read_section(*k);
    }
    return assemble(report);
  }

 private:
  /// The next token, skipping '#' comments; empty at the end of the text.
  std::string_view token() {
    for (;;) {
      const std::string_view t = sc_.next();
      if (t.empty() || t.front() != '#') return t;
      sc_.rest_of_line();
    }
  }

  std::string_view expect(std::string_view what) {
    const std::string_view t = token();
    if (t.empty()) sc_.fail(fmt::format("unexpected end of file, expected {}", what));
    return t;
  }

  double real(std::string_view what) {
    const std::string_view t = expect(what);
    double v = 0;
    if (!parse_double(t, v)) sc_.fail(fmt::format("expected {} (a finite number), found '{}'", what, printable(t)));
    return v;
  }

  std::int64_t integer(std::string_view what) {
    const std::string_view t = expect(what);
    std::int64_t v = 0;
    if (!parse_int(t, v)) sc_.fail(fmt::format("expected {} (an integer), found '{}'", what, printable(t)));
    return v;
  }

  /// An entry count, refused if `per_entry` values each could not fit in the rest of the file.
  std::int64_t count(std::string_view keyword, int per_entry, std::int64_t max = kMaxIndex) {
    const std::int64_t n = integer(fmt::format("the number of {}", keyword));
    if (n < 0) sc_.fail(fmt::format("negative number of {}: {}", keyword, n));
    if (n > max) sc_.fail(fmt::format("{} {} exceed the limit of {}", n, keyword, max));
    // Each value takes at least one character and one separator.
    const auto left = static_cast<std::uint64_t>(remaining());
    if (per_entry > 0 && static_cast<std::uint64_t>(n) > (left + 1) / (2 * static_cast<std::uint64_t>(per_entry)))
      sc_.fail(fmt::format("{} {} declared, more than the {} bytes left in the file can hold", n, keyword, left));
    return n;
  }

  std::size_t remaining() const { return text_size_ - sc_.offset(); }

  /// Reads one section; true at End.
  bool read_section(const Keyword& k) {
    switch (k.kind) {
      case Kind::version: {
        const std::int64_t v = integer("the MeshVersionFormatted value");
        if (v < 1 || v > 4) sc_.fail(fmt::format("MeshVersionFormatted {} is not 1, 2, 3 or 4", v));
        version_ = static_cast<int>(v);
        break;
      }
      case Kind::dimension: {
        const std::int64_t d = integer("the Dimension value");
        if (d != 3) sc_.fail(fmt::format("Dimension {}: only 3-D meshes are supported", d));
        have_dimension_ = true;
        break;
      }
      case Kind::vertices:
        read_vertices();
        break;
      case Kind::hexahedra:
        read_hexahedra();
        break;
      case Kind::required_vertices:
        read_required_vertices();
        break;
      case Kind::non_hex:
        read_non_hex(k);
        break;
      case Kind::skip:
        skip_entries(k.name, count(k.name, k.values), k.values);
        break;
      case Kind::single:
        for (int i = 0; i < k.values; ++i) real(fmt::format("the {} value", k.name));
        break;
      case Kind::solution:
        skip_solution(k.name);
        break;
      case Kind::end:
        return true;
    }
    return false;
  }

  void read_vertices() {
    if (!have_dimension_) sc_.fail("Vertices before Dimension");
    if (have_vertices_) sc_.fail("a second Vertices section");
    const std::int64_t n = count("Vertices", 4);
    points_.resize(static_cast<std::size_t>(n));
    ref_fixed_.assign(static_cast<std::size_t>(n), 0);
    for (std::int64_t i = 0; i < n; ++i) {
      Vec3& p = points_[static_cast<std::size_t>(i)];
      p.x() = real("a vertex x coordinate");
      p.y() = real("a vertex y coordinate");
      p.z() = real("a vertex z coordinate");
      const std::int64_t ref = integer("a vertex reference");
      refs_are_flags_ = refs_are_flags_ && (ref == 0 || ref == 1);
      ref_fixed_[static_cast<std::size_t>(i)] = ref == 1 ? 1 : 0;
    }
    have_vertices_ = true;
  }

  /// A one-based vertex id of entry e of `element`s, as a zero-based index.
  Index vertex_id(std::string_view element, std::int64_t e) {
    const std::string_view t = token();
    std::int64_t id = 0;
    if (t.empty() || !parse_int(t, id))  // messages are only formatted on failure: this is the hot loop
      sc_.fail(t.empty() ? fmt::format("unexpected end of file, expected a vertex id of {} {}", element, e + 1)
                         : fmt::format("expected a vertex id of {} {} (an integer), found '{}'", element, e + 1,
                                       printable(t)));
    if (id < 1 || id > static_cast<std::int64_t>(points_.size()))
      sc_.fail(fmt::format("{} {} has vertex id {} out of range [1, {}]", element, e + 1, id, points_.size()));
    return static_cast<Index>(id - 1);
  }

  void read_hexahedra() {
    if (!have_vertices_) sc_.fail("Hexahedra before Vertices");
    if (have_hexahedra_) sc_.fail("a second Hexahedra section");
    const std::int64_t n = count("Hexahedra", 9);
    hexes_.resize(static_cast<std::size_t>(n));
    blocks_.resize(static_cast<std::size_t>(n));
    for (std::int64_t h = 0; h < n; ++h) {
      for (Index& v : hexes_[static_cast<std::size_t>(h)]) v = vertex_id("hexahedron", h);
      const std::int64_t ref = integer("a hexahedron reference");
      if (ref < std::numeric_limits<Index>::min() || ref > kMaxIndex)
        sc_.fail(fmt::format("hexahedron {} has reference {}, not a 32-bit integer", h + 1, ref));
      blocks_[static_cast<std::size_t>(h)] = static_cast<Index>(ref);
    }
    have_hexahedra_ = true;
  }

  void read_required_vertices() {
    if (!have_vertices_) sc_.fail("RequiredVertices before Vertices");
    const std::int64_t n = count("RequiredVertices", 1);
    required_.reserve(required_.size() + static_cast<std::size_t>(n));
    for (std::int64_t i = 0; i < n; ++i) required_.push_back(vertex_id("required vertex", i));
  }

  void read_non_hex(const Keyword& k) {
    const std::size_t line = sc_.line();
    const std::int64_t n = count(k.name, k.values);
    if (n > 0 && !options_.skip_non_hex)
      parse_error(sc_.file(), fmt::format("line {}", line),
                  fmt::format("{} {} are not hexahedra (read with skip_non_hex to drop them)", n, k.name));
    skip_entries(k.name, n, k.values);
    skipped_ += static_cast<std::size_t>(n);
  }

  /// Skips n entries of `per_entry` numbers (checked to be numbers, so that a wrong count
  /// shows up here rather than as a confusing keyword error later).
  void skip_entries(std::string_view keyword, std::int64_t n, int per_entry) {
    const std::string what = fmt::format("a value of {}", keyword);
    for (std::int64_t i = 0; i < n * per_entry; ++i) {
      const std::string_view t = expect(what);
      double v = 0;
      if (!parse_double(t, v)) sc_.fail(fmt::format("expected {} (a number), found '{}'", what, printable(t)));
    }
  }

  /// "SolAtX n ntypes type..." then n entries whose size follows from the types
  /// (1 scalar, 2 vector, 3 symmetric matrix, 4 matrix).
  void skip_solution(std::string_view keyword) {
    const std::int64_t n = count(keyword, 1);
    const std::int64_t ntypes = integer(fmt::format("the number of {} fields", keyword));
    if (ntypes < 1 || ntypes > 1000) sc_.fail(fmt::format("{} declares {} fields", keyword, ntypes));
    int per_entry = 0;
    for (std::int64_t i = 0; i < ntypes; ++i) {
      const std::int64_t type = integer(fmt::format("a {} field type", keyword));
      constexpr int kSizes[] = {0, 1, 3, 6, 9};
      if (type < 1 || type > 4) sc_.fail(fmt::format("{} field type {} is not 1, 2, 3 or 4", keyword, type));
      per_entry += kSizes[type];
    }
    if (static_cast<std::uint64_t>(n) * static_cast<std::uint64_t>(per_entry) > (remaining() + 1) / 2)
      sc_.fail(fmt::format("{} {} entries declared, more than the {} bytes left can hold", n, keyword, remaining()));
    skip_entries(keyword, n, per_entry);
  }

  HexMesh assemble(ReadReport& report) {
    if (!have_vertices_) sc_.fail("no Vertices section");
    HexMesh mesh;
    mesh.points = std::move(points_);
    mesh.hexes = std::move(hexes_);
    bool any_block = false;
    for (const Index b : blocks_) any_block = any_block || b != 0;
    if (any_block) mesh.blocks = std::move(blocks_);
    bool any_ref_fixed = false;
    for (const std::uint8_t f : ref_fixed_) any_ref_fixed = any_ref_fixed || f;
    if ((refs_are_flags_ && any_ref_fixed) || !required_.empty()) {
      mesh.fixed.assign(mesh.points.size(), 0);
      if (refs_are_flags_) mesh.fixed = std::move(ref_fixed_);
      for (const Index v : required_) mesh.fixed[static_cast<std::size_t>(v)] = 1;
    }
    report.format = fmt::format("MEDIT {}", version_ ? fmt::format("version {}", version_) : "(no version)");
    report.skipped_cells = skipped_;
    return mesh;
  }

 private:
  TextScanner sc_;
  const ReadOptions& options_;
  std::size_t text_size_;
  int version_ = 0;
  bool have_dimension_ = false, have_vertices_ = false, have_hexahedra_ = false;
  bool refs_are_flags_ = true;
  std::vector<Vec3> points_;
  std::vector<std::uint8_t> ref_fixed_;
  std::vector<Hex> hexes_;
  std::vector<Index> blocks_;
  std::vector<Index> required_;
  std::size_t skipped_ = 0;
};

}  // namespace

HexMesh read_medit(const fs::path& file, const ReadOptions& options, ReadReport* report) {
  const std::string text = read_file(file);
  ReadReport local;
  MeditReader reader(text, file, options);
  return reader.read(report ? *report : local);
}

void write_medit(const fs::path& file, const HexMesh& mesh, const WriteOptions&) {
  check_mesh_for_writing(file, mesh);
  write_atomically(file, [&](std::ostream& out) {
    TextOut text(out);
    text.print("MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n{}\n", mesh.points.size());
    for (std::size_t v = 0; v < mesh.points.size(); ++v) {
      const Vec3& p = mesh.points[v];
      text.print("{:.17g} {:.17g} {:.17g} {}\n", p.x(), p.y(), p.z(), mesh.has_fixed() && mesh.fixed[v] ? 1 : 0);
    }
    text.print("\nHexahedra\n{}\n", mesh.hexes.size());
    for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
      const Hex& x = mesh.hexes[h];
      text.print("{} {} {} {} {} {} {} {} {}\n", x[0] + 1, x[1] + 1, x[2] + 1, x[3] + 1, x[4] + 1, x[5] + 1, x[6] + 1,
                 x[7] + 1, mesh.block(static_cast<Index>(h)));
    }
    text.print("\nEnd\n");
    text.flush();
  });
}

}  // namespace isohex::io
