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
/// around its one vertex would be two cones meeting at a point. Such cells are *non-manifold*;
/// the mesher makes the smaller outside parts inside (manifold_fill) until none is left.
/// This is the one place the mesh's topology can differ from marching cubes (which keeps the
/// two outside parts apart).

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

}  // namespace isohex::contour
