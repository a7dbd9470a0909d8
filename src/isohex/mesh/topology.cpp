#include "isohex/mesh/topology.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>

namespace isohex {

namespace {

// A face reference sorted by its sorted vertex ids; ties broken by hex * 6 + face (the same
// order as by hex, then face) so that the order, and hence every numbering derived from it,
// is unique. 20 bytes: on cthead h 2 (585,000 hexes) the keys are the largest transient of
// a mesh's topology.
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

Quad face_vertices(const Hex& h, int f) {
  return {h[kHexFaces[f][0]], h[kHexFaces[f][1]], h[kHexFaces[f][2]], h[kHexFaces[f][3]]};
}

// Every hex face's key, sorted.
std::vector<FaceKey> sorted_face_keys(const HexMesh& mesh) {
  std::vector<FaceKey> keys(mesh.hexes.size() * 6);
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
    for (int f = 0; f < 6; ++f) {
      FaceKey& k = keys[h * 6 + f];
      k.key = face_vertices(mesh.hexes[h], f);
      std::sort(k.key.begin(), k.key.end());
      k.hex_face = static_cast<Index>(h * 6 + static_cast<std::size_t>(f));
    }
  tbb::parallel_sort(keys.begin(), keys.end());
  return keys;
}

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

}  // namespace

std::vector<QuadFace> build_quads(const HexMesh& mesh) {
  const std::vector<FaceKey> keys = sorted_face_keys(mesh);
  // Exactly as many as there are: a guess that falls short makes the vector grow to twice
  // its size with the old one still held (cthead h 2: 140 MB at validate()'s peak instead of 47).
  std::size_t unique = 0;
  for_each_face(keys, [&](std::size_t, std::size_t) { ++unique; });
  std::vector<QuadFace> quads;
  quads.reserve(unique);
  for_each_face(keys, [&](std::size_t i, std::size_t j) {
    QuadFace q;
    q.vertices = face_vertices(mesh.hexes[keys[i].hex()], keys[i].face());
    q.hex[0] = keys[i].hex();
    q.local[0] = static_cast<std::int8_t>(keys[i].face());
    q.hex[1] = j - i > 1 ? keys[i + 1].hex() : -1;
    q.local[1] = static_cast<std::int8_t>(j - i > 1 ? keys[i + 1].face() : -1);
    q.extra_hexes = static_cast<Index>(j - i > 2 ? j - i - 2 : 0);
    quads.push_back(q);
  });
  return quads;
}

std::vector<Quad> boundary_quads(const std::vector<QuadFace>& quads) {
  std::vector<Quad> out;
  for (const QuadFace& q : quads)
    if (q.is_boundary()) out.push_back(q.vertices);
  return out;
}

// The quads used by one hex, in build_quads()'s order, without its vector of every quad.
std::vector<Quad> boundary_quads(const HexMesh& mesh) {
  const std::vector<FaceKey> keys = sorted_face_keys(mesh);
  std::vector<Quad> out;
  for_each_face(keys, [&](std::size_t i, std::size_t j) {
    if (j - i == 1) out.push_back(face_vertices(mesh.hexes[keys[i].hex()], keys[i].face()));
  });
  return out;
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

}  // namespace isohex
