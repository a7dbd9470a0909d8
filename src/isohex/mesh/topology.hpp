#pragma once
/// \file topology.hpp
/// \brief Adjacency of a HexMesh, built on demand: unique quads, edges, vertex→hex incidence.
///
/// Everything here is derived from `mesh.hexes` alone and is deterministic: entities are
/// numbered in the order of their sorted vertex keys, independent of thread count.

#include "isohex/mesh/hex_mesh.hpp"

#include <array>
#include <vector>

namespace isohex {

/// One unique quad of the mesh and the hexes on its two sides.
struct QuadFace {
  Quad vertices;        ///< as seen from hexes[0], counter-clockwise from outside that hex
  Index hex[2];         ///< hex[1] == -1 for a quad with one hex (a boundary quad)
  std::int8_t local[2]; ///< face number (0..5, kHexFaces) within hex[0] / hex[1]
  /// Number of hexes that use this quad beyond two (a non-conformal or non-manifold fault).
  Index extra_hexes = 0;
  [[nodiscard]] bool is_boundary() const { return hex[1] < 0; }
};

/// All unique quads. A quad used by more than two hexes keeps the first two and counts the
/// rest in `extra_hexes`.
std::vector<QuadFace> build_quads(const HexMesh& mesh);

/// The vertices of local face f (kHexFaces) of hex h, counter-clockwise seen from outside h.
inline Quad face_vertices(const Hex& h, int f) {
  return {h[kHexFaces[f][0]], h[kHexFaces[f][1]], h[kHexFaces[f][2]], h[kHexFaces[f][3]]};
}

/// Per hex and local face (kHexFaces), the hex on the face's other side, -1 on the boundary
/// (build_quads()'s hex[0] and hex[1] of each quad, without holding every quad: on cthead at
/// h 2 those were 48 MB). A face used by more than two hexes links its first two only.
std::vector<std::array<Index, 6>> face_neighbours(const HexMesh& mesh);

/// The boundary quads (quads with one hex), each oriented outward (counter-clockwise seen
/// from outside the mesh), in the order of build_quads.
std::vector<Quad> boundary_quads(const HexMesh& mesh);
/// The same, from quads already built.
std::vector<Quad> boundary_quads(const std::vector<QuadFace>& quads);

/// All unique edges as (smaller id, larger id), sorted.
std::vector<std::array<Index, 2>> build_edges(const HexMesh& mesh);

/// Compressed vertex→hex incidence: hexes of vertex v are ids[offsets[v] .. offsets[v+1]),
/// ascending.
struct Incidence {
  std::vector<Index> offsets;
  std::vector<Index> ids;
  [[nodiscard]] std::size_t count(Index v) const { return static_cast<std::size_t>(offsets[v + 1] - offsets[v]); }
};
Incidence vertex_hexes(const HexMesh& mesh);

/// Vertex→element incidence for any list of cells with `corners` vertices each.
template <std::size_t N>
Incidence vertex_cells(const std::vector<std::array<Index, N>>& cells, Index num_vertices) {
  Incidence inc;
  inc.offsets.assign(static_cast<std::size_t>(num_vertices) + 1, 0);
  for (const auto& c : cells)
    for (Index v : c) ++inc.offsets[v + 1];
  for (std::size_t i = 1; i < inc.offsets.size(); ++i) inc.offsets[i] += inc.offsets[i - 1];
  inc.ids.resize(static_cast<std::size_t>(inc.offsets.back()));
  std::vector<Index> fill(inc.offsets.begin(), inc.offsets.end() - 1);
  for (Index e = 0; e < static_cast<Index>(cells.size()); ++e)
    for (Index v : cells[e]) inc.ids[fill[v]++] = e;
  return inc;
}

/// Vertices on the boundary (1) or not (0).
std::vector<std::uint8_t> boundary_vertex_mask(const HexMesh& mesh);

/// The hexes flagged in `keep` (in order) and the vertices they use (numbered in the order the
/// kept hexes first use them), with their blocks, fixed flags and the faces of the face sets
/// that are on kept hexes (a set left empty is dropped). `vertex_id` / `hex_id` (may be null)
/// receive each old vertex's / hex's new id, or -1.
HexMesh keep_hexes(const HexMesh& mesh, const std::vector<std::uint8_t>& keep, std::vector<Index>* vertex_id = nullptr,
                   std::vector<Index>* hex_id = nullptr);

}  // namespace isohex
