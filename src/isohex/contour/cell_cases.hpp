#pragma once
/// \file cell_cases.hpp
/// \brief The 256 inside/outside configurations of a grid cell, seen by the dual hex mesher:
/// which corners share a dual vertex, and which configurations would make the boundary
/// non-manifold.
///
/// Corner c of a cell is at offset (c & 1, (c >> 1) & 1, (c >> 2) & 1); bit c of a mask is
/// set when corner c is inside. Two corners are *adjacent* when they share a cell edge.
///
/// Every inside grid point becomes a hex whose corners are dual vertices of the 8 cells
/// around it. Within one cell, the inside corners form *components* under adjacency; each
/// component gets its own dual vertex ("vertex splitting", as in manifold dual contouring).
/// Two adjacent inside corners always share the vertex (they share a hex face), so the mesh
/// stays conformal, and inside points touching only along an edge or at a vertex get
/// separate vertices, so they do not pinch the boundary. This reproduces the topology of
/// VTK's marching cubes, which also separates inside corners on ambiguous faces and body
/// diagonals.
///
/// Splitting cannot fix the complementary fault: an inside component whose complement in the
/// cell falls apart (e.g. 6 inside corners around two opposite outside corners). The surface
/// around its one vertex would be two cones meeting at a point. Such cells are *non-manifold*
/// and the mesher edits the samples, choosing the edit that keeps marching cubes' topology:
///  - outside parts touching *along an edge* (two outside corners on a face diagonal):
///    marching cubes joins them across that face (inside corners on an ambiguous face are
///    kept apart), so one inside corner of that face is made outside (manifold_carve), which
///    joins them the same way;
///  - outside parts touching only *at a vertex* (body diagonal): marching cubes keeps them
///    apart, so the smaller part is made inside (manifold_fill).
/// These are the places the mesh's topology can still differ from marching cubes.

#include <array>
#include <cstdint>

namespace isohex::contour {

/// What the mesher needs to know about one configuration.
struct CellCase {
  std::uint8_t num_components = 0;           ///< inside components (0 for an all-outside cell)
  std::array<std::int8_t, 8> component{};    ///< component of each inside corner, -1 outside;
                                             ///< components numbered by their lowest corner
  bool manifold = true;                      ///< every component's complement is connected
};

/// The configuration of `mask` (from a table built once).
const CellCase& cell_case(std::uint8_t mask);

/// Corners to make inside so that the non-manifold components of `mask` become manifold: for
/// each such component, the outside corners of all parts of its complement except one. The
/// part kept is the one holding a corner of `fixed_outside` (corners that must stay outside,
/// e.g. beyond the volume's box), else the largest (ties: the lowest corner). 0 when `mask`
/// is manifold. Never returns a corner of `fixed_outside`.
std::uint8_t manifold_fill(std::uint8_t mask, std::uint8_t fixed_outside);

/// True when two parts of a non-manifold component's complement touch along an edge (have
/// corners on a common face diagonal), the contact manifold_carve removes.
bool has_edge_contact(std::uint8_t mask);

/// The inside corner to make outside so that two outside parts touching along an edge join
/// across their face, as marching cubes joins them: of the inside corners on the other
/// diagonal of such faces, the one with the lowest `level` (nearest the isosurface, so the
/// joint opens where the field is weakest; ties: the lowest corner). 0 when `mask` has no
/// edge contact or no candidate is in `allowed`. `level[c]` is the level of inside corner c.
std::uint8_t manifold_carve(std::uint8_t mask, const float level[8], std::uint8_t allowed = 0xff);

/// The inside corners manifold_carve chooses from (0 when `mask` has no edge contact).
std::uint8_t carve_candidates(std::uint8_t mask);

}  // namespace isohex::contour
