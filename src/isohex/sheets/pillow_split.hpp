#pragma once
/// \file pillow_split.hpp
/// \brief Internal to pillow.cpp: how each interface vertex is split (see pillowing.md).
///
/// Around an interface vertex v, the *cells* are the hexes containing v plus, when boundary
/// quads are interface quads, the exterior. Cells on the same side (shrink set or not; the
/// exterior counts as outside) that share a face containing v form *fans*. Every fan gets its
/// own vertex, except that at a *pinched edge* (an interface edge with four or more interface
/// quads around it, or two or more where it ends on the boundary) the fans on one side of the
/// edge are merged at both its ends: the new hexes' side faces along the edge then pair up
/// around the other side's fans, so that each side face is shared by exactly two new hexes.
/// The merged fans form a *group*; each group is one vertex of the pillowed mesh.
///
/// Which side to merge at a pinched edge is free topologically, but not geometrically: a
/// group's vertex can only move if some direction sees all the interface quad corners it is
/// behind, and at most one group per vertex (the *keeper*, which keeps v's position and id)
/// may be blind. The merge sides are chosen by a small local search until every vertex has a
/// placement and every pinched edge pairs its side faces.

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/sheets/pillow.hpp"

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace isohex::detail {

/// An interface quad, oriented counter-clockwise seen from outside its shrink-set hex (its
/// normal points away from the shrink set).
struct InterfaceQuad {
  Quad v;
  Index shrink_hex;
  Index outside_hex;  ///< -1: a boundary quad (the exterior is its outside)
};

/// Area vector of a quad (half the cross product of its diagonals).
inline Vec3 area_vector(const HexMesh& m, const Quad& q) {
  return 0.5 * (m.points[q[2]] - m.points[q[0]]).cross(m.points[q[3]] - m.points[q[1]]);
}

/// One vertex of the pillowed mesh at an interface vertex.
struct SplitVertex {
  Index original;
  Index id;                 ///< `original` for the keeper, else a new id (appended in order)
  Vec3 displacement;        ///< full displacement before halving (zero for the keeper)
  bool shrink_side = false;
  bool blind = false;       ///< no direction sees its corners: the vertex is folded
  std::vector<Index> hexes; ///< the hexes that take this vertex (the exterior is not listed)
};

/// How the interface is split.
struct InterfaceSplit {
  std::vector<SplitVertex> vertices;  ///< per interface vertex, its groups; keepers included
  /// Per interface quad and corner: the vertex id on the outside / shrink side.
  std::vector<Quad> outside_ids, shrink_ids;
  std::size_t interface_vertices = 0;
  std::size_t pinched_edges = 0;
  std::size_t flipped_edges = 0;       ///< pinched edges whose shrink side was merged instead
  std::vector<std::uint8_t> folded;    ///< per original vertex: some group there is blind
  /// (vertex, hex): at a vertex where a pinch cannot be placed by any choice of merge sides,
  /// the hex whose flip (into / out of the shrink set) undoes it; by vertex.
  std::vector<std::pair<Index, Index>> flip_candidates;
  /// Pinched edges whose side faces could not be paired (never seen in the tests): the mesh
  /// would not be conformal there.
  std::vector<std::array<Index, 2>> unpaired_edges;
};

/// Splits the interface. `nb[h][f]` is the hex across face f of h (-1 on the boundary);
/// `hex_inc` is vertex_hexes(mesh).
InterfaceSplit split_interface(const HexMesh& mesh, const std::vector<std::uint8_t>& in,
                               const std::vector<std::array<Index, 6>>& nb, const std::vector<InterfaceQuad>& iq,
                               const PillowOptions& options, const Incidence& hex_inc);

}  // namespace isohex::detail
