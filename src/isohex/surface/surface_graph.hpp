#pragma once
/// \file surface_graph.hpp
/// \brief Internal to smooth_surface(): the adjacency it needs (boundary quads and edges,
/// creases, the band of interior vertices under the boundary) and the vertex colouring that
/// makes its parallel sweeps deterministic.

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/mesh/topology.hpp"

#include <cstdint>
#include <vector>

namespace isohex::surface_detail {

/// Boundary adjacency of a hex mesh.
struct SurfaceGraph {
  std::vector<Quad> quads;              ///< boundary quads, outward
  Incidence vertex_quads;               ///< vertex → boundary quads (over all vertices)
  Incidence vertex_hexes;               ///< vertex → hexes
  Incidence boundary_neighbours;        ///< vertex → vertices joined to it by a boundary edge
  std::vector<std::uint8_t> on_boundary;  ///< 1 for boundary vertices
  std::vector<std::uint8_t> on_crease;    ///< 1 for ends of a crease or non-manifold boundary edge
};

/// Builds the graph; `crease_cos` is the cosine of the crease angle (edges whose two quads'
/// unit normals have a dot product below it are creases).
SurfaceGraph build_surface_graph(const HexMesh& mesh, double crease_cos);

/// Interior vertices within `layers` hex layers of the boundary (a vertex sharing a hex with
/// a boundary vertex is in layer 1), ascending, excluding those with `pinned` set.
std::vector<Index> interior_band(const HexMesh& mesh, const SurfaceGraph& graph, int layers,
                                 const std::vector<std::uint8_t>& pinned);

/// Splits `vertices` into classes no two members of which share a hex (greedy, in the given
/// order, so the result depends on nothing but the input). Classes keep ascending order.
std::vector<std::vector<Index>> colour_classes(const std::vector<Index>& vertices, const HexMesh& mesh,
                                               const Incidence& vertex_hexes);

}  // namespace isohex::surface_detail
