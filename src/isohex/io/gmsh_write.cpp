// Gmsh 4.1 (.msh) writer, ASCII or binary.
//
// Layout: one volume entity per block (tag = position in the block table + 1) in a
// physical volume whose tag is the block's file id and whose name is block_name(value);
// one surface entity per block that owns boundary quads, holding those quads, all in the
// physical surface 1 "boundary" and each listed as a bounding surface of its volume; each
// non-empty named face set (HexMesh::face_sets, e.g. a cut's faces) is its own physical surface
// (tag 2, 3, ... in the sets' order, named as the set) over one more surface entity with its
// quads, oriented outward from their hexes; sets of the same quads (the two sides of an
// interface) share one entity, as Gmsh wants each element once.
// Gmsh's 8-node hexahedron numbers its corners as VTK does (0-1-2-3 one face, i+4 above i),
// so hexes are written as they are; quads are the outward boundary quads.
//
// Every node sits in exactly one entity block, as Gmsh's own files have it: boundary nodes
// in the surface of the first boundary quad using them, other nodes in the volume of the
// first hex using them (unused nodes in the first volume). Node tags are vertex index + 1,
// hex tags hex index + 1 and quad tags follow, so the reader restores both orders.

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/format_support.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/io/solver_sets.hpp"
#include "isohex/mesh/topology.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <ostream>
#include <string>
#include <vector>

namespace isohex::io {

namespace {

namespace fs = std::filesystem;

/// Gmsh element type numbers.
constexpr int kGmshQuad4 = 3;
constexpr int kGmshHex8 = 5;

/// Output of the numbers in Gmsh's two encodings: ASCII tokens, or native binary with
/// `size_t` (8 bytes) for counts and tags of nodes/elements and `int` for entity data.
class MshOut {
 public:
  MshOut(std::ostream& out, bool binary) : text_(out), binary_(binary) {}

  void text(std::string_view s) { text_.print("{}", s); }
  /// A count or a node/element tag (size_t in binary).
  void size(std::uint64_t v) { binary_ ? raw(v) : (sep(), text_.print("{}", v)); }
  /// An entity tag, dimension, type or physical tag (int in binary).
  void tag(int v) { binary_ ? raw(v) : (sep(), text_.print("{}", v)); }
  void real(double v) { binary_ ? raw(v) : (sep(), text_.print("{:.17g}", v)); }
  /// Ends a line of ASCII values (binary data has no lines).
  void eol() {
    if (!binary_) text_.print("\n");
    line_start_ = true;
  }
  /// Starts a section; ASCII and binary sections both open with a text line.
  void begin(std::string_view name) { text_.print("${}\n", name); }
  void end(std::string_view name) { text_.print("{}$End{}\n", binary_ ? "\n" : "", name); }
  void flush() { text_.flush(); }

 private:
  template <class T>
  void raw(T v) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &v, sizeof(T));
    text_.print("{}", std::string_view(bytes, sizeof(T)));
  }
  void sep() {
    if (!line_start_) text_.print(" ");
    line_start_ = false;
  }
  TextOut text_;
  bool binary_;
  bool line_start_ = true;
};

struct Box {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -Vec3::Constant(std::numeric_limits<double>::infinity());
  void add(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
};

void write_box(MshOut& out, const Box& b) {
  for (int d = 0; d < 3; ++d) out.real(b.lo[d]);
  for (int d = 0; d < 3; ++d) out.real(b.hi[d]);
}

Quad sorted_quad(const HexMesh& mesh, Index h, int f) {
  Quad q = face_vertices(mesh.hexes[static_cast<std::size_t>(h)], f);
  std::sort(q.begin(), q.end());
  return q;
}

// The named face sets as surface entities (see the file comment).
struct SetEntities {
  std::vector<const FaceSet*> named;   // the non-empty sets: physical tags 2, 3, ...
  std::vector<const FaceSet*> sets;    // the set of each entity ...
  std::vector<std::vector<int>> tags;  // ... and its physical tags: 1 too when its quads are all boundary quads
  std::size_t faces = 0;               // quads in all entities
  std::vector<std::uint8_t> taken;     // per boundary face: in such an entity, not in its block's surface
};

SetEntities face_set_entities(const HexMesh& mesh, const std::vector<BoundaryFace>& boundary) {
  SetEntities e;
  e.taken.assign(boundary.size(), 0);
  std::vector<std::pair<Quad, std::size_t>> on_boundary;
  for (std::size_t i = 0; i < boundary.size(); ++i) on_boundary.emplace_back(sorted_quad(mesh, boundary[i].hex, boundary[i].face), i);
  std::sort(on_boundary.begin(), on_boundary.end());
  std::vector<std::vector<Quad>> keys_of;
  for (const FaceSet& fs : mesh.face_sets) {
    if (fs.faces.empty()) continue;
    e.named.push_back(&fs);
    const int tag = static_cast<int>(e.named.size()) + 1;
    std::vector<Quad> keys;
    for (const auto& [h, f] : fs.faces) keys.push_back(sorted_quad(mesh, h, f));
    std::sort(keys.begin(), keys.end());
    if (const auto same = std::find(keys_of.begin(), keys_of.end(), keys); same != keys_of.end()) {
      e.tags[static_cast<std::size_t>(same - keys_of.begin())].push_back(tag);
      continue;
    }
    std::vector<std::size_t> found;
    for (const auto& k : keys) {
      const auto it = std::lower_bound(on_boundary.begin(), on_boundary.end(), std::make_pair(k, std::size_t{0}));
      if (it == on_boundary.end() || it->first != k) break;
      found.push_back(it->second);
    }
    const bool boundary_set = found.size() == keys.size();
    if (boundary_set)
      for (const std::size_t i : found) e.taken[i] = 1;
    e.sets.push_back(&fs);
    e.tags.push_back(boundary_set ? std::vector<int>{1, tag} : std::vector<int>{tag});
    keys_of.push_back(std::move(keys));
    e.faces += fs.faces.size();
  }
  return e;
}

void write_msh(std::ostream& stream, const HexMesh& mesh, bool binary) {
  const BlockTable blocks = block_table(mesh);
  const std::vector<BoundaryFace> faces = boundary_faces(mesh);
  const SetEntities named = face_set_entities(mesh, faces);
  // A mesh without hexes still needs one volume to hold its nodes.
  const std::size_t num_volumes = std::max<std::size_t>(blocks.values.size(), mesh.points.empty() ? 0 : 1);
  auto block_of_hex = [&](Index h) { return static_cast<std::size_t>(blocks.of_hex[static_cast<std::size_t>(h)]); };

  // Entity of each node: (dimension, position); -1 = not yet placed.
  std::vector<int> node_dim(mesh.points.size(), -1);
  std::vector<std::size_t> node_entity(mesh.points.size(), 0);
  std::vector<Box> volume_box(num_volumes), surface_box(num_volumes);
  std::vector<std::vector<std::size_t>> surface_faces(num_volumes);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const std::size_t b = block_of_hex(faces[f].hex);
    if (!named.taken[f]) surface_faces[b].push_back(f);
    for (const int k : kHexFaces[static_cast<std::size_t>(faces[f].face)]) {
      const Index v = mesh.hexes[static_cast<std::size_t>(faces[f].hex)][static_cast<std::size_t>(k)];
      surface_box[b].add(mesh.points[static_cast<std::size_t>(v)]);
      if (node_dim[static_cast<std::size_t>(v)] < 0) {
        node_dim[static_cast<std::size_t>(v)] = 2;
        node_entity[static_cast<std::size_t>(v)] = b;
      }
    }
  }
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
    for (const Index v : mesh.hexes[h]) {
      volume_box[block_of_hex(static_cast<Index>(h))].add(mesh.points[static_cast<std::size_t>(v)]);
      if (node_dim[static_cast<std::size_t>(v)] < 0) {
        node_dim[static_cast<std::size_t>(v)] = 3;
        node_entity[static_cast<std::size_t>(v)] = block_of_hex(static_cast<Index>(h));
      }
    }
  for (std::size_t v = 0; v < mesh.points.size(); ++v)
    if (node_dim[v] < 0) {
      node_dim[v] = 3;
      volume_box[0].add(mesh.points[v]);
    }
  for (Box& b : volume_box)  // a volume without nodes (cannot happen with hexes) gets an empty box at 0
    if (!(b.lo.array() <= b.hi.array()).all()) b.lo = b.hi = Vec3::Zero();
  std::size_t num_surfaces = 0;
  for (const auto& s : surface_faces) num_surfaces += s.empty() ? 0 : 1;
  const auto face_box = [&](const FaceSet& fs) {
    Box box;
    for (const auto& [h, f] : fs.faces)
      for (const Index v : face_vertices(mesh.hexes[static_cast<std::size_t>(h)], f)) box.add(mesh.points[static_cast<std::size_t>(v)]);
    return box;
  };

  MshOut out(stream, binary);
  out.begin("MeshFormat");
  out.text(binary ? "4.1 1 8\n" : "4.1 0 8\n");
  if (binary) {
    out.tag(1);  // lets a reader detect the byte order
    out.text("\n");
  }
  out.text("$EndMeshFormat\n");

  // Physical names are text in both encodings.
  out.begin("PhysicalNames");
  out.text(fmt::format("{}\n", blocks.values.size() + (faces.empty() ? 0 : 1) + named.named.size()));
  if (!faces.empty()) out.text("2 1 \"boundary\"\n");
  for (std::size_t j = 0; j < named.named.size(); ++j) out.text(fmt::format("2 {} \"{}\"\n", j + 2, named.named[j]->name));
  for (std::size_t b = 0; b < blocks.values.size(); ++b)
    out.text(fmt::format("3 {} \"{}\"\n", blocks.file_ids[b], block_name(blocks.values[b])));
  out.text("$EndPhysicalNames\n");

  out.begin("Entities");
  for (const std::uint64_t n : {std::uint64_t{0}, std::uint64_t{0}, std::uint64_t{num_surfaces + named.sets.size()}, std::uint64_t{num_volumes}})
    out.size(n);
  out.eol();
  for (std::size_t b = 0; b < num_volumes; ++b) {
    if (surface_faces[b].empty()) continue;
    out.tag(static_cast<int>(b) + 1);
    write_box(out, surface_box[b]);
    out.size(1);
    out.tag(1);  // physical surface "boundary"
    out.size(0);  // no bounding curves: the mesh has no curve entities
    out.eol();
  }
  for (std::size_t j = 0; j < named.sets.size(); ++j) {
    out.tag(static_cast<int>(num_volumes + j) + 1);
    write_box(out, face_box(*named.sets[j]));
    out.size(named.tags[j].size());
    for (const int tag : named.tags[j]) out.tag(tag);
    out.size(0);
    out.eol();
  }
  for (std::size_t b = 0; b < num_volumes; ++b) {
    out.tag(static_cast<int>(b) + 1);
    write_box(out, volume_box[b]);
    const bool physical = b < blocks.values.size();
    out.size(physical ? 1 : 0);
    if (physical) out.tag(blocks.file_ids[b]);
    out.size(surface_faces[b].empty() ? 0 : 1);
    if (!surface_faces[b].empty()) out.tag(static_cast<int>(b) + 1);
    out.eol();
  }
  out.end("Entities");

  // Nodes, entity block by entity block: surfaces then volumes, tags ascending in each.
  std::vector<std::vector<Index>> nodes_of[2];  // [0] surfaces, [1] volumes
  for (auto& n : nodes_of) n.resize(num_volumes);
  for (std::size_t v = 0; v < mesh.points.size(); ++v)
    nodes_of[node_dim[v] == 2 ? 0 : 1][node_entity[v]].push_back(static_cast<Index>(v));
  std::size_t node_blocks = 0;
  for (const auto& n : nodes_of)
    for (const auto& e : n) node_blocks += e.empty() ? 0 : 1;
  out.begin("Nodes");
  out.size(node_blocks);
  out.size(mesh.points.size());
  out.size(mesh.points.empty() ? 0 : 1);
  out.size(mesh.points.size());
  out.eol();
  for (int d = 0; d < 2; ++d)
    for (std::size_t e = 0; e < num_volumes; ++e) {
      const std::vector<Index>& ids = nodes_of[d][e];
      if (ids.empty()) continue;
      out.tag(d == 0 ? 2 : 3);
      out.tag(static_cast<int>(e) + 1);
      out.tag(0);  // no parametric coordinates
      out.size(ids.size());
      out.eol();
      for (const Index v : ids) {
        out.size(static_cast<std::uint64_t>(v) + 1);
        out.eol();
      }
      for (const Index v : ids) {
        for (int k = 0; k < 3; ++k) out.real(mesh.points[static_cast<std::size_t>(v)][k]);
        out.eol();
      }
    }
  out.end("Nodes");

  // Elements: hexes per volume (hex order), then quads per surface.
  std::vector<std::vector<Index>> hexes_of(num_volumes);
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) hexes_of[block_of_hex(static_cast<Index>(h))].push_back(static_cast<Index>(h));
  const std::size_t num_elements = mesh.hexes.size() + faces.size() - static_cast<std::size_t>(std::count(named.taken.begin(), named.taken.end(), 1)) + named.faces;
  std::size_t element_blocks = num_surfaces + named.sets.size();
  for (const auto& h : hexes_of) element_blocks += h.empty() ? 0 : 1;
  out.begin("Elements");
  out.size(element_blocks);
  out.size(num_elements);
  out.size(num_elements ? 1 : 0);
  out.size(num_elements);
  out.eol();
  for (std::size_t b = 0; b < num_volumes; ++b) {
    if (hexes_of[b].empty()) continue;
    out.tag(3);
    out.tag(static_cast<int>(b) + 1);
    out.tag(kGmshHex8);
    out.size(hexes_of[b].size());
    out.eol();
    for (const Index h : hexes_of[b]) {
      out.size(static_cast<std::uint64_t>(h) + 1);
      for (const Index v : mesh.hexes[static_cast<std::size_t>(h)]) out.size(static_cast<std::uint64_t>(v) + 1);
      out.eol();
    }
  }
  std::uint64_t quad_tag = mesh.hexes.size();
  // One block of quads in surface entity `entity`: face(i) is the (hex, local face) of quad i.
  const auto write_quads = [&](std::size_t entity, std::size_t count, const auto& face) {
    out.tag(2);
    out.tag(static_cast<int>(entity) + 1);
    out.tag(kGmshQuad4);
    out.size(count);
    out.eol();
    for (std::size_t i = 0; i < count; ++i) {
      const auto [hex, local] = face(i);
      out.size(++quad_tag);
      const Hex& h = mesh.hexes[static_cast<std::size_t>(hex)];
      for (const int k : kHexFaces[static_cast<std::size_t>(local)])
        out.size(static_cast<std::uint64_t>(h[static_cast<std::size_t>(k)]) + 1);
      out.eol();
    }
  };
  for (std::size_t b = 0; b < num_volumes; ++b)
    if (!surface_faces[b].empty())
      write_quads(b, surface_faces[b].size(), [&](std::size_t i) {
        const BoundaryFace& f = faces[surface_faces[b][i]];
        return std::pair<Index, int>(f.hex, f.face);
      });
  for (std::size_t j = 0; j < named.sets.size(); ++j)
    write_quads(num_volumes + j, named.sets[j]->faces.size(), [&](std::size_t i) {
      return std::pair<Index, int>(named.sets[j]->faces[i].first, named.sets[j]->faces[i].second);
    });
  out.end("Elements");
  out.flush();
}

}  // namespace

void write_gmsh(const fs::path& file, const HexMesh& mesh, const WriteOptions& options) {
  check_mesh_for_writing(file, mesh);
  write_atomically(file, [&](std::ostream& out) { write_msh(out, mesh, options.msh_binary); });
}

}  // namespace isohex::io
