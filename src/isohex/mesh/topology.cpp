#include "isohex/mesh/topology.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>

namespace isohex {

namespace {

// A face reference sorted by its sorted vertex ids; ties broken by hex * 6 + face (the same
// order as by hex, then face) so that the order, and hence every numbering derived from it,
// is unique.
struct FaceKey {
  std::array<Index, 4> key;
  Index hex_face;
  bool operator<(const FaceKey& o) const {
    if (key != o.key) return key < o.key;
    return hex_face < o.hex_face;
  }
  [[nodiscard]] Index hex() const { return hex_face / 6; }
  [[nodiscard]] int face() const { return static_cast<int>(hex_face % 6); }
};

// Calls f(i, j) for each run keys[i..j) of one face (sorted keys).
template <class F>
void for_each_face(const std::vector<FaceKey>& keys, F&& f) {
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i + 1;
    while (j < keys.size() && keys[j].key == keys[i].key) ++j;
    f(i, j);
    i = j;
  }
}

// The three local faces (kHexFaces) at each corner of a hex.
constexpr std::array<std::array<int, 3>, 8> kCornerFaces = [] {
  std::array<std::array<int, 3>, 8> cf{};
  std::array<std::size_t, 8> n{};
  for (int f = 0; f < 6; ++f)
    for (int c : kHexFaces[static_cast<std::size_t>(f)]) {
      const auto k = static_cast<std::size_t>(c);
      cf[k][n[k]++] = f;
    }
  return cf;
}();

// Adds face f of hex h to `keys` if v is its smallest vertex.
void add_face_from(const HexMesh& mesh, Index h, int f, Index v, std::vector<FaceKey>& keys) {
  FaceKey fk;
  fk.key = face_vertices(mesh.hexes[h], f);
  if (std::min(std::min(fk.key[0], fk.key[1]), std::min(fk.key[2], fk.key[3])) != v) return;
  std::sort(fk.key.begin(), fk.key.end());
  fk.hex_face = h * 6 + f;
  keys.push_back(fk);
}

// The keys of the faces whose smallest vertex is v, sorted (into `keys`): those of the hexes
// around v that have v on them, the three at v's corner (every boundary or face scan runs this
// for every vertex; looking at all six faces of each hex was 3.8 % of smoothing ECR block_in).
void faces_from(const HexMesh& mesh, const Incidence& inc, Index v, std::vector<FaceKey>& keys) {
  keys.clear();
  for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) {
    const Index h = inc.ids[k];
    if (k > inc.offsets[v] && inc.ids[k - 1] == h) continue;  // v twice in h (listed in hex order)
    if (k + 1 < inc.offsets[v + 1] && inc.ids[k + 1] == h) {  // ... at two corners: every face
      for (int f = 0; f < 6; ++f) add_face_from(mesh, h, f, v, keys);
      continue;
    }
    int c = 0;
    while (mesh.hexes[h][static_cast<std::size_t>(c)] != v) ++c;
    for (int f : kCornerFaces[static_cast<std::size_t>(c)]) add_face_from(mesh, h, f, v, keys);
  }
  std::sort(keys.begin(), keys.end());
}

// Vertices per block of the face scans below: blocks in parallel, each face met once, at its
// smallest vertex.
constexpr std::size_t kFaceBlock = 1024;
std::size_t face_blocks(const HexMesh& mesh) { return (mesh.points.size() + kFaceBlock - 1) / kFaceBlock; }

// Calls f(keys, i, j) for each face (the run keys[i..j) of its references, sorted) whose
// smallest vertex lies in block b, in vertex order.
template <class F>
void faces_of_block(const HexMesh& mesh, const Incidence& inc, std::size_t b, F&& f) {
  thread_local std::vector<FaceKey> keys;
  for (std::size_t v = b * kFaceBlock; v < std::min(mesh.points.size(), (b + 1) * kFaceBlock); ++v) {
    faces_from(mesh, inc, static_cast<Index>(v), keys);
    for_each_face(keys, [&](std::size_t i, std::size_t j) { f(keys, i, j); });
  }
}

// One T per face for which make(keys, i, j, out) returns true (writing it to *out unless out is
// null), in the order of a sort of every hex face's key (the faces of smallest vertex v come
// before those of v + 1), without holding every key: on cthead h 2 those were 70 MB, the peak
// of the pillow stage's validation. Blocks of vertices in parallel: a first pass counts, a
// second writes each block's faces at its offset (the same output for any thread count).
template <class T, class Make>
std::vector<T> collect_faces(const HexMesh& mesh, Make&& make) {
  const Incidence inc = vertex_hexes(mesh);
  const std::size_t blocks = face_blocks(mesh);
  const auto scan = [&](std::size_t b, T* out) {
    std::size_t n = 0;
    faces_of_block(mesh, inc, b, [&](const std::vector<FaceKey>& keys, std::size_t i, std::size_t j) {
      n += make(keys, i, j, out ? out + n : nullptr);
    });
    return n;
  };
  std::vector<std::size_t> offset(blocks + 1, 0);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) { offset[b + 1] = scan(b, nullptr); });
  for (std::size_t b = 0; b < blocks; ++b) offset[b + 1] += offset[b];
  std::vector<T> out(offset.back());
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) { scan(b, out.data() + offset[b]); });
  return out;
}

}  // namespace

std::vector<QuadFace> build_quads(const HexMesh& mesh) {
  return collect_faces<QuadFace>(mesh, [&](const std::vector<FaceKey>& keys, std::size_t i, std::size_t j, QuadFace* q) {
    if (!q) return true;
    q->vertices = face_vertices(mesh.hexes[keys[i].hex()], keys[i].face());
    q->hex[0] = keys[i].hex();
    q->local[0] = static_cast<std::int8_t>(keys[i].face());
    q->hex[1] = j - i > 1 ? keys[i + 1].hex() : -1;
    q->local[1] = static_cast<std::int8_t>(j - i > 1 ? keys[i + 1].face() : -1);
    q->extra_hexes = static_cast<Index>(j - i > 2 ? j - i - 2 : 0);
    return true;
  });
}

std::vector<std::array<Index, 6>> face_neighbours(const HexMesh& mesh) {
  std::vector<std::array<Index, 6>> nb(mesh.hexes.size());
  for (auto& n : nb) n.fill(-1);
  const Incidence inc = vertex_hexes(mesh);
  // Each face writes only its own hexes' entries.
  tbb::parallel_for(std::size_t{0}, face_blocks(mesh), [&](std::size_t b) {
    faces_of_block(mesh, inc, b, [&](const std::vector<FaceKey>& keys, std::size_t i, std::size_t j) {
      if (j - i < 2) return;
      nb[keys[i].hex()][keys[i].face()] = keys[i + 1].hex();
      nb[keys[i + 1].hex()][keys[i + 1].face()] = keys[i].hex();
    });
  });
  return nb;
}

std::vector<Quad> boundary_quads(const std::vector<QuadFace>& quads) {
  std::vector<Quad> out;
  for (const QuadFace& q : quads)
    if (q.is_boundary()) out.push_back(q.vertices);
  return out;
}

// The quads used by one hex, in build_quads()'s order, without its vector of every quad.
std::vector<Quad> boundary_quads(const HexMesh& mesh) {
  return collect_faces<Quad>(mesh, [&](const std::vector<FaceKey>& keys, std::size_t i, std::size_t j, Quad* q) {
    if (j - i != 1) return false;
    if (q) *q = face_vertices(mesh.hexes[keys[i].hex()], keys[i].face());
    return true;
  });
}

std::vector<std::array<Index, 2>> build_edges(const HexMesh& mesh) {
  std::vector<std::array<Index, 2>> edges(mesh.hexes.size() * 12);
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
    for (int e = 0; e < 12; ++e) {
      Index a = mesh.hexes[h][kHexEdges[e][0]], b = mesh.hexes[h][kHexEdges[e][1]];
      edges[h * 12 + e] = {std::min(a, b), std::max(a, b)};
    }
  tbb::parallel_sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

Incidence vertex_hexes(const HexMesh& mesh) { return vertex_cells(mesh.hexes, mesh.num_vertices()); }

std::vector<std::uint8_t> boundary_vertex_mask(const HexMesh& mesh) {
  std::vector<std::uint8_t> mask(mesh.points.size(), 0);
  for (const Quad& q : boundary_quads(mesh))
    for (Index v : q) mask[v] = 1;
  return mask;
}

HexMesh keep_hexes(const HexMesh& mesh, const std::vector<std::uint8_t>& keep, std::vector<Index>* vertex_id,
                   std::vector<Index>* hex_id) {
  std::vector<Index> vid(mesh.points.size(), -1), hid(mesh.hexes.size(), -1);
  HexMesh out;
  for (Index h = 0; h < mesh.num_hexes(); ++h) {
    if (!keep[h]) continue;
    hid[h] = out.num_hexes();
    Hex hx = mesh.hexes[h];
    for (Index& v : hx) {
      if (vid[v] < 0) vid[v] = out.num_vertices(), out.points.push_back(mesh.points[v]);
      v = vid[v];
    }
    out.hexes.push_back(hx);
    if (mesh.has_blocks()) out.blocks.push_back(mesh.blocks[h]);
  }
  if (mesh.has_fixed()) {
    out.fixed.assign(out.points.size(), 0);
    for (std::size_t v = 0; v < vid.size(); ++v)
      if (vid[v] >= 0) out.fixed[static_cast<std::size_t>(vid[v])] = mesh.fixed[v];
  }
  for (const FaceSet& fs : mesh.face_sets) {
    FaceSet kept{fs.name, {}};
    for (const auto& [h, f] : fs.faces)
      if (hid[h] >= 0) kept.faces.push_back({hid[h], f});
    if (!kept.faces.empty()) out.face_sets.push_back(std::move(kept));
  }
  if (vertex_id) *vertex_id = std::move(vid);
  if (hex_id) *hex_id = std::move(hid);
  return out;
}

}  // namespace isohex
