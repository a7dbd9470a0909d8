#pragma once
// Private to cut.cpp: what each vertex keeps to during a cut, moving vertices onto it, and the
// classification of hexes into the cut's two sides (see sheets/cut.hpp for the steps).

#include "isohex/contour/region.hpp"
#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/slide.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace isohex::internal {

// One thing a vertex keeps to: cut surface `surface`, or (surface < 0) the input's boundary
// triangles that face `facing` (one face of it: a feature edge keeps to two, a corner to three).
struct Keep {
  int surface = -1;
  Vec3 facing = Vec3::Zero();
};

using Keeps = std::vector<Keep>;

// Per boundary vertex of `mesh`: the level sets of `surfaces` it is on; where it is on none,
// the directions of its boundary quads more than `feature_degrees` apart (the triangles).
std::vector<Keeps> boundary_keeps(const HexMesh& mesh, const std::vector<contour::LevelSet>& surfaces,
                                  double feature_degrees);

inline bool on_surface(const Keeps& k, int surface) {
  return std::any_of(k.begin(), k.end(), [&](const Keep& e) { return e.surface == surface; });
}

// Moves vertices onto what they keep to: level sets (by index into `levels`) and the input's
// boundary triangles (to `tri_tol`), never farther than `reach`; `step` is the input's mean
// edge length.
struct Placer {
  const std::vector<contour::LevelSet>& levels;
  const BoundarySurface& tris;
  double tri_tol, reach, step;
  const Aabb* domain = nullptr;  // places outside it are refused

  // Moves x onto everything in `keeps` at once: Newton steps, each the least step that zeroes
  // the linearised levels (a level set's L, or the signed distance to the plane of the nearest
  // triangle facing the keep's way), else by turns, else from a point of a volume's isosurface
  // found by bracketing. False if none settles within `reach`, or (place()) it lies outside
  // `domain`; x is unchanged then.
  bool place(Vec3& x, const Keeps& keeps) const;
  bool place_anywhere(Vec3& x, const Keeps& keeps) const;
  bool newton(Vec3& x, const Keeps& keeps) const;
  // Alternating projections onto each of `keeps` in turn (slower than Newton steps, but they
  // settle where the triangles' planes change under the steps: a bumpy boundary).
  bool by_turns(Vec3& x, const Keeps& keeps) const;
};

// The optimisers' constraint for a vertex: one or two things to keep to (two faces of the
// input's triangles: a feature edge); three or more pin it.
BoundarySurface::Constraint constraint_of(const Keeps& k);

// The sides of a cut (1 = inside) by the sign at each hex's centroid, or for a hex on the
// boundary at the mean of its boundary faces' centres (the staircase then meets the boundary
// where the surface does); outside within `tie_band` (CutOptions::tie_band) of the surface.
std::vector<std::uint8_t> first_sides(const HexMesh& m, const std::vector<std::array<Index, 6>>& nb,
                                      const contour::LevelSet& surface, double tie_band);

// The interior faces on an earlier cut's surface (all four vertices on it), as their two hexes,
// with the side of the face's centre: both hexes must take it, or the face would be on the
// interface too and collapse onto the curve of the two surfaces.
struct EarlierFace {
  Index h, g;
  std::uint8_t side;
};

std::vector<EarlierFace> faces_on_earlier_cuts(const HexMesh& m, const std::vector<std::array<Index, 6>>& nb,
                                               const std::vector<Keeps>& keeps, int first_cut,
                                               const contour::LevelSet& surface);

// Round after round until nothing changes: the hexes on faces of earlier cuts take those faces'
// sides, and a hex with four or more faces towards the other side moves across, one at a time
// (`moved` counts those); hexes flagged in `locked` stay.
void settle_sides(const HexMesh& m, const std::vector<std::array<Index, 6>>& nb, const std::vector<EarlierFace>& earlier,
                  const std::vector<std::uint8_t>& locked, std::vector<std::uint8_t>& side, std::size_t& moved);

// Interface vertices the cut cannot reach: on a surface (the boundary, an earlier cut) that the
// cut does not cross near them, or, inside, too far from a volume's isosurface that only grazes
// the staircase there: their hexes join one side (that of the vertex's sign, or of those of its hexes
// already locked) and are locked there, so that the interface leaves them and settle_sides() does
// not move them back. Returns how many there were.
std::size_t unreachable_to_one_side(const HexMesh& m, const Incidence& inc, const std::vector<std::uint8_t>& side,
                                    const std::vector<Keeps>& keeps, int cut_id, const Placer& placer,
                                    std::vector<std::uint8_t>& next, std::vector<std::uint8_t>& locked);

// Edges on a curve of two surfaces (the boundary's rim on a box face, an earlier cut's crease)
// whose two ends are both interface vertices: both would go to the one point where the cut
// crosses the curve and collapse the edge. One end's hexes join one side (the side of those
// locked before, else its majority) and are locked there; the end that moves fewer hexes.
// An edge is on the curve when its midpoint is on both surfaces (within a quarter of its length;
// not an edge across a patch between two branches of the curve). Returns how many ends moved.
std::size_t doubled_curve_ends(const HexMesh& m, const std::vector<contour::LevelSet>& levels, const Incidence& inc,
                               const std::vector<std::array<Index, 2>>& edges, const std::vector<Keeps>& keeps,
                               double cos_limit, std::vector<std::uint8_t>& side, std::vector<std::uint8_t>& locked);

}  // namespace isohex::internal
