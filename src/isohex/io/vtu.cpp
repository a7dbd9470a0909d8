// Reader for VTK XML UnstructuredGrid (.vtu) files. The XML is parsed by xml_lite, array
// data decoded by vtk_xml_data; this file turns pieces, points and cells into a HexMesh.
#include "isohex/io/mesh_io.hpp"

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/text_scanner.hpp"
#include "isohex/io/vtk_xml_data.hpp"
#include "isohex/io/vtk_xml_settings.hpp"
#include "isohex/io/xml_lite.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <type_traits>

namespace isohex::io {

namespace {

namespace fs = std::filesystem;
using vtkxml::Array;

constexpr int kVtkVoxel = 11;
constexpr int kVtkHexahedron = 12;
constexpr std::int64_t kMaxIndex = INT32_MAX;

/// CellData array names taken as the block id, in order of preference.
constexpr std::string_view kBlockNames[] = {"block", "BlockId", "CellEntityIds", "gmsh:physical", "MaterialIds"};

std::string_view cell_type_name(int type) {
  switch (type) {
    case 0: return "empty cell";
    case 1: return "vertex";
    case 2: return "poly-vertex";
    case 3: return "line";
    case 4: return "poly-line";
    case 5: return "triangle";
    case 6: return "triangle strip";
    case 7: return "polygon";
    case 8: return "pixel";
    case 9: return "quad";
    case 10: return "tetrahedron";
    case 11: return "voxel";
    case 12: return "hexahedron";
    case 13: return "wedge";
    case 14: return "pyramid";
    case 15: return "pentagonal prism";
    case 16: return "hexagonal prism";
    case 24: return "quadratic tetrahedron";
    case 25: return "quadratic hexahedron";
    case 29: return "triquadratic hexahedron";
    case 42: return "polyhedron";
    default: return "non-hexahedral cell";
  }
}

/// `v` as an int64; false if it is not an integer in int64's range.
template <class T>
bool as_int64(T v, std::int64_t& out) {
  if constexpr (std::is_floating_point_v<T>) {
    if (!(v >= -9.2e18 && v <= 9.2e18) || v != std::trunc(v)) return false;
  } else if constexpr (std::is_unsigned_v<T>) {
    if (static_cast<std::uint64_t>(v) > static_cast<std::uint64_t>(INT64_MAX)) return false;
  }
  out = static_cast<std::int64_t>(v);
  return true;
}

/// Everything read from one <Piece>.
struct Piece {
  HexMesh mesh;
  bool has_blocks = false, has_fixed = false;
};

/// Reads a whole file: settings from <VTKFile>, then each <Piece>.
class VtuReader {
 public:
  VtuReader(const fs::path& file, const ReadOptions& options, ReadReport& report)
      : file_(file), options_(options), report_(report), text_(read_file(file)),
        doc_(xml::parse(text_, file)), ctx_{file_, text_} {}

  HexMesh run() {
    vtkxml::read_settings(doc_, "UnstructuredGrid", "UnstructuredGrid (.vtu) meshes", ctx_);
    const xml::Element& root = doc_.root();
    const xml::Element* grid = doc_.only_child(root, "UnstructuredGrid", file_);
    if (!grid) fail(root.offset, "<VTKFile> has no <UnstructuredGrid> element");
    const std::vector<const xml::Element*> pieces = doc_.children(*grid, "Piece");
    if (pieces.empty()) fail(grid->offset, "<UnstructuredGrid> has no <Piece> element");
    HexMesh mesh;
    std::vector<Piece> read;
    for (std::size_t i = 0; i < pieces.size(); ++i) {
      piece_label_ = pieces.size() > 1 ? fmt::format("Piece {}: ", i) : std::string();
      read.push_back(read_piece(*pieces[i]));
    }
    report_.format = describe(pieces.size());
    return merge(read);
  }

 private:
  [[noreturn]] void fail(std::size_t offset, std::string_view what) const {
    parse_error(file_, xml::position(text_, offset), fmt::format("{}{}", piece_label_, what));
  }

  std::int64_t count_attribute(const xml::Element& e, std::string_view key) const {
    const std::string* v = e.attribute(key);
    std::int64_t n = -1;
    if (!v || !parse_int(*v, n) || n < 0) fail(e.offset, fmt::format("<{}> needs a non-negative integer {}", e.name, key));
    if (n > kMaxIndex) fail(e.offset, fmt::format("{} {} exceeds isohex's limit of {}", key, n, kMaxIndex));
    return n;
  }

  static int components(const xml::Element& e) {
    const std::string* v = e.attribute("NumberOfComponents");
    std::int64_t n = 1;
    if (v && !parse_int(*v, n)) return -1;
    return static_cast<int>(std::clamp<std::int64_t>(n, -1, 1 << 20));
  }

  /// The child DataArray of `parent` named `name` (any name if empty), or nullptr.
  const xml::Element* data_array(const xml::Element* parent, std::string_view name) const {
    if (!parent) return nullptr;
    for (const xml::Element* e : doc_.children(*parent, "DataArray")) {
      const std::string* n = e->attribute("Name");
      if (name.empty() || (n && *n == name)) return e;
    }
    return nullptr;
  }

  Array decode(const xml::Element& e, std::size_t count) {
    Array a = vtkxml::decode(e, count, ctx_);
    formats_.insert(a.format());
    return a;
  }

  /// Decodes a one-component integer array (offsets, types, connectivity, block ids).
  Array decode_integers(const xml::Element& e, std::size_t count) {
    const std::string* name = e.attribute("Name");
    vtkxml::Scalar s;
    const std::string* type = e.attribute("type");
    if (type && vtkxml::scalar_from_name(*type, s) && !vtkxml::is_integer(s))
      fail(e.offset, fmt::format("DataArray '{}' must hold integers, not {}", name ? *name : "", *type));
    if (components(e) != 1) fail(e.offset, fmt::format("DataArray '{}' must have one component", name ? *name : ""));
    return decode(e, count);
  }

  Piece read_piece(const xml::Element& piece) {
    const std::int64_t np = count_attribute(piece, "NumberOfPoints");
    const std::int64_t nc = count_attribute(piece, "NumberOfCells");
    Piece out;
    read_points(piece, static_cast<std::size_t>(np), out.mesh);
    const std::vector<std::size_t> skipped = read_cells(piece, static_cast<std::size_t>(nc), out.mesh);
    out.has_fixed = read_fixed(piece, out.mesh);
    out.has_blocks = read_blocks(piece, static_cast<std::size_t>(nc), skipped, out.mesh);
    return out;
  }

  void read_points(const xml::Element& piece, std::size_t np, HexMesh& mesh) {
    const xml::Element* da = data_array(doc_.only_child(piece, "Points", file_), "");
    if (!da) {
      if (np == 0) return;
      fail(piece.offset, "<Piece> has points but no <Points><DataArray>");
    }
    if (components(*da) != 3) fail(da->offset, "the Points DataArray must have NumberOfComponents=\"3\"");
    const Array a = decode(*da, np * 3);
    mesh.points.resize(np);
    vtkxml::visit(a, [&](auto v) {
      for (std::size_t i = 0; i < np; ++i) mesh.points[i] = Vec3(double(v[3 * i]), double(v[3 * i + 1]), double(v[3 * i + 2]));
    });
    for (std::size_t i = 0; i < np; ++i)
      if (!mesh.points[i].allFinite()) fail(da->offset, fmt::format("point {} has a non-finite coordinate (NaN or Inf)", i));
  }

  std::vector<std::int64_t> read_offsets(const xml::Element& da, std::size_t nc) {
    const Array a = decode_integers(da, nc);
    std::vector<std::int64_t> off(nc);
    vtkxml::visit(a, [&](auto v) {
      std::int64_t prev = 0;
      for (std::size_t i = 0; i < nc; ++i) {
        std::int64_t x = -1;
        if (!as_int64(v[i], x) || x < prev)
          fail(da.offset, fmt::format("offsets[{}] = {} is below the previous offset {} or out of range (offsets "
                                      "must not decrease)", i, v[i], prev));
        off[i] = prev = x;
      }
    });
    return off;
  }

  std::vector<std::uint8_t> read_types(const xml::Element& da, std::size_t nc) {
    const Array a = decode_integers(da, nc);
    std::vector<std::uint8_t> types(nc);
    vtkxml::visit(a, [&](auto v) {
      for (std::size_t i = 0; i < nc; ++i) {
        std::int64_t t = -1;
        if (!as_int64(v[i], t) || t < 0 || t > 255)
          fail(da.offset, fmt::format("types[{}] = {} is not a VTK cell type", i, v[i]));
        types[i] = static_cast<std::uint8_t>(t);
      }
    });
    return types;
  }

  /// Reads the hexes; returns the indices of the cells skipped (non-hex, under skip_non_hex).
  std::vector<std::size_t> read_cells(const xml::Element& piece, std::size_t nc, HexMesh& mesh) {
    const xml::Element* cells = doc_.only_child(piece, "Cells", file_);
    if (nc == 0) return {};
    if (!cells) fail(piece.offset, "<Piece> has cells but no <Cells> element");
    const xml::Element* conn_da = data_array(cells, "connectivity");
    const xml::Element* off_da = data_array(cells, "offsets");
    const xml::Element* types_da = data_array(cells, "types");
    if (!conn_da || !off_da || !types_da)
      fail(cells->offset, "<Cells> needs DataArrays named connectivity, offsets and types");
    const std::vector<std::int64_t> off = read_offsets(*off_da, nc);
    const std::vector<std::uint8_t> types = read_types(*types_da, nc);
    const Array conn = decode_integers(*conn_da, static_cast<std::size_t>(off.back()));
    std::vector<std::size_t> skipped;
    mesh.hexes.reserve(nc);
    const auto np = static_cast<std::int64_t>(mesh.points.size());
    vtkxml::visit(conn, [&](auto v) {
      for (std::size_t c = 0; c < nc; ++c) {
        const int type = types[c];
        const std::size_t begin = c ? static_cast<std::size_t>(off[c - 1]) : 0;
        const std::size_t size = static_cast<std::size_t>(off[c]) - begin;
        if (type != kVtkHexahedron && type != kVtkVoxel) {
          if (!options_.skip_non_hex)
            fail(types_da->offset, fmt::format("cell {} is a {} (VTK type {}), not a hexahedron (skip_non_hex / "
                                               "--skip-non-hex drops such cells)",
                                               c, cell_type_name(type), type));
          ++report_.skipped_cells;
          skipped.push_back(c);
          continue;
        }
        if (size != 8)
          fail(off_da->offset, fmt::format("cell {} is a {} with {} vertices instead of 8", c, cell_type_name(type), size));
        Hex h;
        for (int k = 0; k < 8; ++k) {
          std::int64_t id = -1;
          if (!as_int64(v[begin + static_cast<std::size_t>(k)], id) || id < 0 || id >= np)
            fail(conn_da->offset, fmt::format("cell {} refers to vertex {}, but the piece has {} points", c,
                                              v[begin + static_cast<std::size_t>(k)], np));
          h[static_cast<std::size_t>(k)] = static_cast<Index>(id);
        }
        // A voxel numbers its corners lexicographically (x fastest); hex order walks each
        // quad around, so corners 2,3 and 6,7 trade places.
        if (type == kVtkVoxel) {
          std::swap(h[2], h[3]);
          std::swap(h[6], h[7]);
        }
        mesh.hexes.push_back(h);
      }
    });
    return skipped;
  }

  bool read_fixed(const xml::Element& piece, HexMesh& mesh) {
    const xml::Element* da = data_array(doc_.only_child(piece, "PointData", file_), "fixed");
    if (!da) return false;
    if (components(*da) != 1) fail(da->offset, "the 'fixed' point array must have one component");
    const Array a = decode(*da, mesh.points.size());
    mesh.fixed.resize(mesh.points.size());
    vtkxml::visit(a, [&](auto v) {
      for (std::size_t i = 0; i < mesh.fixed.size(); ++i) mesh.fixed[i] = v[i] != 0 ? 1 : 0;
    });
    return true;
  }

  /// The block id array: the first CellData array with a known name, one integer component.
  /// Same-named arrays of other shapes (e.g. float-valued material fields) are not ids.
  const xml::Element* block_array(const xml::Element* cell_data) const {
    for (std::string_view name : kBlockNames) {
      const xml::Element* da = data_array(cell_data, name);
      const std::string* type = da ? da->attribute("type") : nullptr;
      vtkxml::Scalar s;
      if (type && vtkxml::scalar_from_name(*type, s) && vtkxml::is_integer(s) && components(*da) == 1) return da;
    }
    return nullptr;
  }

  bool read_blocks(const xml::Element& piece, std::size_t nc, const std::vector<std::size_t>& skipped,
                   HexMesh& mesh) {
    const xml::Element* da = block_array(doc_.only_child(piece, "CellData", file_));
    if (!da) return false;
    const Array a = decode_integers(*da, nc);
    mesh.blocks.resize(mesh.hexes.size());
    vtkxml::visit(a, [&](auto v) {
      std::size_t next_skip = 0, h = 0;
      for (std::size_t c = 0; c < nc; ++c) {
        if (next_skip < skipped.size() && skipped[next_skip] == c) {
          ++next_skip;
          continue;
        }
        std::int64_t b = 0;
        if (!as_int64(v[c], b) || b < INT32_MIN || b > INT32_MAX)
          fail(da->offset, fmt::format("block id {} of cell {} does not fit in 32 bits", v[c], c));
        mesh.blocks[h++] = static_cast<Index>(b);
      }
    });
    return true;
  }

  /// Concatenates pieces, offsetting vertex ids; blocks/fixed default to 0 where a piece lacks them.
  HexMesh merge(std::vector<Piece>& pieces) const {
    if (pieces.size() == 1) return std::move(pieces.front().mesh);
    HexMesh m;
    const bool blocks = std::any_of(pieces.begin(), pieces.end(), [](const Piece& p) { return p.has_blocks; });
    const bool fixed = std::any_of(pieces.begin(), pieces.end(), [](const Piece& p) { return p.has_fixed; });
    for (Piece& p : pieces) {
      const std::int64_t base = static_cast<std::int64_t>(m.points.size());
      if (base + static_cast<std::int64_t>(p.mesh.points.size()) > kMaxIndex)
        parse_error(file_, "Piece", fmt::format("the pieces hold more than isohex's limit of {} points", kMaxIndex));
      for (Hex h : p.mesh.hexes) {
        for (Index& id : h) id += static_cast<Index>(base);
        m.hexes.push_back(h);
      }
      m.points.insert(m.points.end(), p.mesh.points.begin(), p.mesh.points.end());
      if (blocks) {
        if (p.has_blocks)
          m.blocks.insert(m.blocks.end(), p.mesh.blocks.begin(), p.mesh.blocks.end());
        else
          m.blocks.resize(m.hexes.size(), 0);
      }
      if (fixed) {
        if (p.has_fixed)
          m.fixed.insert(m.fixed.end(), p.mesh.fixed.begin(), p.mesh.fixed.end());
        else
          m.fixed.resize(m.points.size(), 0);
      }
    }
    return m;
  }

  /// E.g. "VTK XML appended raw zlib UInt64".
  std::string describe(std::size_t pieces) const {
    std::string s = "VTK XML";
    for (const std::string& f : formats_) s += " " + f;
    const bool binary = std::any_of(formats_.begin(), formats_.end(), [](const std::string& f) { return f != "ascii"; });
    if (binary) {
      if (ctx_.zlib) s += " zlib";
      s += ctx_.header_bytes == 8 ? " UInt64" : " UInt32";
      if (ctx_.big_endian) s += " BigEndian";
    }
    if (pieces > 1) s += fmt::format(" ({} pieces)", pieces);
    return s;
  }

  const fs::path& file_;
  const ReadOptions& options_;
  ReadReport& report_;
  std::string text_;
  xml::Document doc_;
  vtkxml::Context ctx_;
  std::string piece_label_;
  std::set<std::string> formats_;
};

}  // namespace

HexMesh read_vtu(const fs::path& file, const ReadOptions& options, ReadReport* report) {
  ReadReport local;
  return VtuReader(file, options, report ? *report : local).run();
}

}  // namespace isohex::io
