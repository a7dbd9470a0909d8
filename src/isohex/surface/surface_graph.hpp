#pragma once
/// \file surface_graph.hpp
/// \brief Internal to smooth_surface(): the adjacency it needs (boundary quads and edges,
/// creases, the band of interior vertices under the boundary) and the vertex colouring that
/// makes its parallel sweeps deterministic.

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/mesh/topology.hpp"

#include <cstdint>
#include <functional>
#include <vector>

namespace isohex::surface_detail {

/// Boundary adjacency of a hex mesh.
struct SurfaceGraph {
  std::vector<Quad> quads;              ///< boundary quads, outward
  std::vector<Index> quad_hex;          ///< per boundary quad, its hex
  std::vector<std::int8_t> quad_face;   ///< per boundary quad, its face number in that hex (kHexFaces)
  Incidence vertex_quads;               ///< vertex → boundary quads (over all vertices)
  Incidence vertex_hexes;               ///< vertex → hexes
  Incidence boundary_neighbours;        ///< vertex → vertices joined to it by a boundary edge
  std::vector<std::uint8_t> on_boundary;  ///< 1 for boundary vertices
  std::vector<std::uint8_t> on_crease;    ///< 1 for ends of a crease or non-manifold boundary edge
  std::vector<std::uint8_t> on_feature;   ///< 1 for ends of a crease that the vertex normals confirm (see below)
};

/// Builds the graph; `crease_cos` is the cosine of the crease angle (edges whose two quads'
/// unit normals have a dot product below it are creases). A crease is also a *feature* when
/// `vertex_normal` (a unit normal per vertex, e.g. the isosurface's) turns by more than
/// `vertex_crease_cos` between its two ends, or when no `vertex_normal` is given: a fold of
/// the quads where the surface itself is smooth is no feature to keep.
SurfaceGraph build_surface_graph(const HexMesh& mesh, double crease_cos,
                                 const std::function<Vec3(Index)>& vertex_normal = {}, double vertex_crease_cos = 1);

/// Interior vertices within `layers` hex layers of the boundary (a vertex sharing a hex with
/// a boundary vertex is in layer 1), ascending, excluding those with `pinned` set.
std::vector<Index> interior_band(const HexMesh& mesh, const SurfaceGraph& graph, int layers,
                                 const std::vector<std::uint8_t>& pinned);

/// Splits `vertices` into classes no two members of which share a hex (greedy, in the given
/// order, so the result depends on nothing but the input). Classes keep ascending order.
std::vector<std::vector<Index>> colour_classes(const std::vector<Index>& vertices, const HexMesh& mesh,
                                               const Incidence& vertex_hexes);

/// Splits boundary vertices `vertices` into classes such that no member of a class reads
/// another: v reads the vertices of the boundary quads around v and around its boundary
/// neighbours (what the max–min pass's score of v looks at) and, when `guarded` is given, the
/// vertices of the hexes around v (the hex guard of the move). Greedy, in the given order.
std::vector<std::vector<Index>> read_disjoint_classes(const std::vector<Index>& vertices, const SurfaceGraph& graph,
                                                      const HexMesh* guarded = nullptr);

}  // namespace isohex::surface_detail
