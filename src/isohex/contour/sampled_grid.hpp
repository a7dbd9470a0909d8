#pragma once
/// \file sampled_grid.hpp
/// \brief The inside/outside classification of the dual-contouring grid, padded with a layer
/// of outside points, and the edits made to it before meshing: manifold repair and removal
/// of small components.

#include "isohex/contour/dual_contour.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace isohex::contour {

/// Inside flags on the grid padded by one point on every side. Padded index (I, J, K) is grid
/// point (I − 1, J − 1, K − 1); points with a padded index 0 or P − 1 are padding, always
/// outside. Cell (I, J, K) spans padded points I..I+1, J..J+1, K..K+1.
struct SampledGrid {
  DualGrid grid;
  Aabb domain;
  std::array<std::size_t, 3> padded{3, 3, 3};  ///< points per axis, padding included
  std::vector<std::uint8_t> inside;             ///< 1 = inside, x fastest
  /// min_k L_k at each point as sampled (+0 on padding and where L == 0 exactly, -0 where NaN);
  /// the repair flips the points nearest the isosurface (lowest |level|).
  std::vector<float> level;

  [[nodiscard]] std::size_t index(std::size_t i, std::size_t j, std::size_t k) const {
    return i + padded[0] * (j + padded[1] * k);
  }
  [[nodiscard]] std::size_t num_cells(int axis) const { return padded[axis] - 1; }
  /// World position of padded point (i, j, k).
  [[nodiscard]] Vec3 position(std::size_t i, std::size_t j, std::size_t k) const {
    return grid.origin + grid.h * Vec3(static_cast<double>(i) - 1, static_cast<double>(j) - 1, static_cast<double>(k) - 1);
  }
  [[nodiscard]] bool is_padding(std::size_t i, std::size_t j, std::size_t k) const {
    return i == 0 || j == 0 || k == 0 || i + 1 == padded[0] || j + 1 == padded[1] || k + 1 == padded[2];
  }
  [[nodiscard]] bool is_padding_at(std::size_t p) const {
    return is_padding(p % padded[0], p / padded[0] % padded[1], p / (padded[0] * padded[1]));
  }
  /// A sample (not padding) whose level is exactly 0 (not NaN): outside, on the isosurface.
  [[nodiscard]] bool on_isosurface(std::size_t p) const {
    return level[p] == 0.0f && !std::signbit(level[p]) && !is_padding_at(p);
  }
  /// Bit c set when corner c (offset (c&1, c>>1&1, c>>2&1)) of cell (i, j, k) is inside.
  [[nodiscard]] std::uint8_t cell_mask(std::size_t i, std::size_t j, std::size_t k) const { return cell_mask_at(index(i, j, k)); }
  /// The same for the cell whose lowest corner has padded index `cell`.
  [[nodiscard]] std::uint8_t cell_mask_at(std::size_t cell) const;
  /// Padded index of corner c (offset (c&1, c>>1&1, c>>2&1)) of the cell whose lowest corner is `cell`.
  [[nodiscard]] std::size_t corner_at(std::size_t cell, int c) const {
    const auto u = static_cast<std::size_t>(c);
    return cell + (u & 1) + padded[0] * (u >> 1 & 1) + padded[0] * padded[1] * (u >> 2 & 1);
  }
  /// Bit c set when corner c of cell (i, j, k) is padding.
  [[nodiscard]] std::uint8_t padding_mask(std::size_t i, std::size_t j, std::size_t k) const;
};

/// Samples the region at every grid point (in parallel). Throws isohex::Error if the grid
/// would have more than 2^31 points.
SampledGrid sample_region(const Region& region, const DualGrid& grid);

/// What repair_manifold changed.
struct RepairCounts {
  std::size_t carved = 0;     ///< inside points made outside
  std::size_t filled = 0;     ///< outside points made inside
  std::size_t simple = 0;     ///< of those, simple points (no change of topology)
  std::size_t relocated = 0;  ///< of those, flips moving one-sample cavities or tunnels (two per move; topology kept)
  std::size_t forced = 0;     ///< of those, edits that may change the topology
  std::size_t degenerate = 0;             ///< of the filled, points of zero-volume cavities
  std::size_t degenerate_components = 0;  ///< zero-volume cavities filled
  std::size_t zero_level = 0;  ///< of the filled, samples at L == 0 on a real surface (fill_zero_level_samples)
  std::size_t pinch = 0;       ///< of the filled, pinches of zero width (fill_shared_pins)
  std::size_t thin = 0;        ///< of the carved, samples of filaments thinner than a fraction of a cell (carve_thin_features)
  struct Edit {
    std::size_t point;  ///< padded index
    RepairKind kind;
  };
  std::vector<Edit> edits;  ///< every flip, in the order made (degenerate, then zero_level ones first, forced ones last)
  std::size_t rounds = 0;
};

/// Makes the grid manifold, keeping the topology marching cubes gives the samples wherever it
/// can. First (fill_degenerate_cavities) it fills the zero-volume cavities, which are not part
/// of the solid's topology, and (fill_zero_level_samples) makes inside the samples at L == 0
/// on which dual contouring would put several vertices, where that is a simple flip (again
/// after step 2); then:
///  1. short sequences of simple flips (is_simple_6_18): for each non-manifold cell, the
///     shortest sequence of up to 5 simple flips, the first a corner of the cell and each next
///     one a corner of a non-manifold cell beside the flip before, that lowers the number of
///     non-manifold cells; the one nearest the isosurface (lowest Σ|level|);
///  2. where none exists, the first of these that mends the cell:
///     a. cavity moves: a corner of the cell that is a one-sample cavity (outside, its 18
///        neighbours inside: a cavity of its own in marching cubes' topology) is made inside,
///        and an inside point within 2 samples whose 26 neighbours are then all inside (so the
///        new cavity merges with nothing and makes no non-manifold cell), next to the
///        isosurface, is made outside: the pair with the lowest |level| sum. One cavity gone,
///        an identical one made: components and Euler characteristic kept;
///     b. prepared sequences: 2 or 3 simple flips, the last a corner of the cell and each
///        earlier one a 26-neighbour of the next (it makes the next one simple: the tip of a
///        one-sample-thick finger before its last point, a point beside a cavity before the
///        cavity);
///     c. the deep search: up to 32 simple flips, each mending the cell it is a corner of
///        without raising the count (a defect walked along a structure: two one-sample-thick
///        fingers joined at their base, zipped up to their tips), at most 20,000 simple-point
///        tests per cell;
///     d. tunnel moves (handle_move.hpp): a corner of the cell whose flip closes or makes one
///        tunnel or handle, and a point within 2 samples whose flip then undoes that change
///        of genus, together lowering the count (one tunnel moved: topology kept);
///     then 1 again around what changed;
///  3. forced edits, in two monotone phases: while some cell has outside parts touching
///     along an edge, inside points are made outside (manifold_carve); then, while some cell
///     is non-manifold, outside points are made inside (manifold_fill; this can create new
///     edge contacts, which it fills too).
/// Every step of 1 and 2 lowers the number of non-manifold cells, so the repair ends. Cells
/// are taken in grid order and the searches are sequential, so the result is the same for
/// any thread count.
RepairCounts repair_manifold(SampledGrid& g);

/// Fills the cavities of zero volume: the parts of the outside points under marching cubes'
/// adjacency for them (18: across faces and face diagonals) that are enclosed by inside points
/// (no padding), whose every sample has L == 0 exactly (a sample of an integer scan equal to
/// the isovalue), and that contain no whole cell. Their isosurface {L = 0} is then a point,
/// segments or doubly covered squares, never a surface around a volume: dual contouring would
/// put every dual vertex around them onto it (a closed boundary of collapsed quads, degenerate
/// hexes). Islands, the mirror case, cannot occur: inside points have L > 0. Sequential, in
/// grid order. Adds the fills to `counts` (kind degenerate) and returns the cavities filled.
std::size_t fill_degenerate_cavities(SampledGrid& g, RepairCounts& counts);

/// Makes inside, in grid order and in rounds until none is left, each outside sample at L == 0
/// (on a real surface: the zero-volume cavities are filled before) on which more than one cell
/// has all its crossings, where that flip is simple for marching cubes' (6, 18) topology and
/// makes no cell non-manifold. dual_contour.cpp puts a crossing at the outside end of an edge
/// when that end is at L == 0, so such cells' dual vertices all go onto that one grid point
/// (for a trilinear field their isosurface is that point): collapsed boundary quads and
/// degenerate hexes that no smoothing can mend. Inside, the sample is a corner of their hexes
/// instead. Run before and after the topology-preserving repair (whose flips beside such a
/// sample can make it shared). Adds the fills to `counts` (kind zero_level) and returns their
/// number.
std::size_t fill_zero_level_samples(SampledGrid& g, RepairCounts& counts);

/// Carves the filaments thinner than `max_fraction` of a cell from their tips: in grid order
/// and in rounds until none is left, each inside sample that
///  - is one sample thick along at least two axes (both neighbours outside on each: a sample
///    of a filament, a speck, or a strip one sample wide and thick),
///  - is within `max_fraction` cells of the isosurface along a grid edge (the sampled levels'
///    linear crossing L / (L − L_q) to an outside, not padding, neighbour q at L_q ≤ 0), and
///  - is a simple point for marching cubes' (6, 18) topology, or has no inside face neighbour
///    (a speck, which would be a component of one hex)
/// is made outside. Such a sample's hex has four or more faces on the boundary round a
/// cross-section far below a cell: its boundary quads fold round the filament, and no
/// placement of the pillow hexes on them reaches a scaled Jacobian of 0.2 (cthead's skin at
/// h 3: wisps one voxel thick). The solid loses at most `max_fraction` cells of thickness
/// there; every other part of the surface is kept. Sequential, so the result is the same for
/// any thread count. Adds the carves to `counts` (kind thin, in `carved` and `thin`) and
/// returns their number.
std::size_t carve_thin_features(SampledGrid& g, double max_fraction, RepairCounts& counts);

/// Labels the face-connected parts of the inside points (which are the connected parts of
/// the hex mesh) and removes those with fewer than `min_points` points. Returns the numbers
/// of parts removed and kept, and of points removed.
struct ComponentCounts {
  std::size_t removed = 0, kept = 0, removed_points = 0;
};
ComponentCounts remove_small_components(SampledGrid& g, std::size_t min_points);

}  // namespace isohex::contour
