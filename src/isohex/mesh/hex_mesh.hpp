#pragma once
/// \file hex_mesh.hpp
/// \brief The hexahedral mesh: plain arrays of coordinates and hexes, nothing derived.
///
/// Node order is VTK's (and Exodus', Verdict's): 0-1-2-3 one quad, 4-5-6-7 the opposite
/// quad with node i+4 joined to node i. A positively oriented hex has 0-1-2-3
/// counter-clockwise when seen from node 4. Topology (quads, edges, incidence) is built on
/// demand by the functions in topology.hpp; algorithms are free functions over HexMesh.

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products on Vec3

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace isohex {

using Index = std::int32_t;      ///< vertex or element id
using Vec3 = Eigen::Vector3d;    ///< a point in world coordinates
using Hex = std::array<Index, 8>;   ///< 8 vertex ids in VTK order
using Quad = std::array<Index, 4>;  ///< 4 vertex ids, counter-clockwise seen from outside

/// A named set of hex faces: a side set (Exodus), an element-based surface (Abaqus). Faces are
/// (hex, local face of kHexFaces). Made by cuts (sheets/cut.hpp) for each cut surface; only
/// the writers read them, and algorithms that renumber hexes leave them to their caller.
struct FaceSet {
  std::string name;  ///< letters, digits and '_', starting with a letter (a valid Abaqus name)
  std::vector<std::pair<Index, std::int8_t>> faces;
};

/// An all-hexahedral mesh.
struct HexMesh {
  std::vector<Vec3> points;        ///< vertex coordinates
  std::vector<Hex> hexes;          ///< 8 vertex ids per hex, VTK order
  std::vector<Index> blocks;       ///< block (material) id per hex; empty means all block 0
  std::vector<std::uint8_t> fixed; ///< 1 = vertex held fixed by optimizers; empty means none
  std::vector<FaceSet> face_sets;  ///< named face sets (side sets); empty means none

  [[nodiscard]] Index num_vertices() const { return static_cast<Index>(points.size()); }
  [[nodiscard]] Index num_hexes() const { return static_cast<Index>(hexes.size()); }
  [[nodiscard]] bool has_blocks() const { return !blocks.empty(); }
  [[nodiscard]] bool has_fixed() const { return !fixed.empty(); }
  /// Block id of hex `h` (0 when the mesh has no blocks).
  [[nodiscard]] Index block(Index h) const { return blocks.empty() ? 0 : blocks[h]; }
  /// The 8 corner coordinates of hex `h`, VTK order.
  [[nodiscard]] std::array<Vec3, 8> corners(Index h) const {
    std::array<Vec3, 8> c;
    for (int i = 0; i < 8; ++i) c[i] = points[hexes[h][i]];
    return c;
  }
  /// The mean of hex `h`'s corners.
  [[nodiscard]] Vec3 centroid(Index h) const {
    Vec3 c = Vec3::Zero();
    for (Index v : hexes[h]) c += points[v];
    return c / 8;
  }
};

/// The 6 faces of a hex in VTK's order, each listed counter-clockwise seen from outside
/// a positively oriented hex (so each face's normal points out of the hex).
inline constexpr std::array<std::array<int, 4>, 6> kHexFaces = {{
    {0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 7, 6, 2}, {0, 3, 2, 1}, {4, 5, 6, 7}}};

/// The 12 edges of a hex in VTK's order.
inline constexpr std::array<std::array<int, 2>, 12> kHexEdges = {{
    {0, 1}, {1, 2}, {3, 2}, {0, 3}, {4, 5}, {5, 6}, {7, 6}, {4, 7}, {0, 4}, {1, 5}, {3, 7}, {2, 6}}};

/// For corner k, its three edge neighbours (a, b, c) such that (Pa-Pk, Pb-Pk, Pc-Pk) is a
/// right-handed frame in a positive hex. The table Verdict uses for corner Jacobians.
inline constexpr std::array<std::array<int, 3>, 8> kCornerNeighbors = {{
    {1, 3, 4}, {2, 0, 5}, {3, 1, 6}, {0, 2, 7}, {7, 5, 0}, {4, 6, 1}, {5, 7, 2}, {6, 4, 3}}};

}  // namespace isohex
