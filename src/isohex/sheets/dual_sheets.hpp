#pragma once
/// \file dual_sheets.hpp
/// \brief The dual sheets of a hex mesh (Shepherd et al. 2006, §3.1–3.2).
///
/// A hex has three groups of four parallel edges. A sheet is an equivalence class of mesh
/// edges under "opposite within a hex" (union-find over each hex's three groups); its hexes
/// are those that have an edge in the class, and in the dual it is the surface crossing
/// those edges. A sheet *self-intersects* where one hex has two of its edge groups in the
/// same sheet. A boundary quad is *captured* by the sheet of the edges of its hex that are
/// perpendicular to it (§3.2, Lemma 2); a boundary component is best captured by one sheet,
/// which boundary pillowing achieves.

#include "isohex/mesh/hex_mesh.hpp"

#include <cstddef>
#include <vector>

namespace isohex {

/// The sheet structure of a mesh.
struct SheetReport {
  std::size_t num_sheets = 0;
  /// Sheet of each edge group of each hex: hex_sheets[h][g], g = 0 (edges 0-1 direction),
  /// 1 (0-3) and 2 (0-4).
  std::vector<std::array<Index, 3>> hex_sheets;
  std::vector<std::size_t> sheet_sizes;    ///< hexes per sheet (a self-intersecting hex counts once)
  std::vector<Index> self_intersecting;    ///< sheets with a self-intersection, ascending
  std::size_t self_intersecting_hexes = 0; ///< hexes where a sheet meets itself
  /// Per boundary component (connected through shared boundary edges, numbered in the order
  /// of their first boundary quad in build_quads): the sheets capturing it, ascending.
  std::vector<std::vector<Index>> boundary_capture;
  std::vector<std::size_t> boundary_component_quads;  ///< boundary quads per component
  std::size_t multi_boundary_hexes = 0;    ///< hexes with two or more boundary faces
};

/// Extracts the sheets of a mesh whose vertex ids are in range (validate() first).
SheetReport extract_sheets(const HexMesh& mesh);

}  // namespace isohex
