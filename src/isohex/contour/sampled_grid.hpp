#pragma once
/// \file sampled_grid.hpp
/// \brief The inside/outside classification of the dual-contouring grid, padded with a layer
/// of outside points, and the edits made to it before meshing: manifold repair and removal
/// of small components.

#include "isohex/contour/dual_contour.hpp"

#include <array>
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
  /// min_k L_k at each point as sampled (0 on padding and where NaN); the repair flips the
  /// points nearest the isosurface (lowest |level|).
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
  /// Bit c set when corner c (offset (c&1, c>>1&1, c>>2&1)) of cell (i, j, k) is inside.
  [[nodiscard]] std::uint8_t cell_mask(std::size_t i, std::size_t j, std::size_t k) const { return cell_mask_at(index(i, j, k)); }
  /// The same for the cell whose lowest corner has padded index `cell`.
  [[nodiscard]] std::uint8_t cell_mask_at(std::size_t cell) const;
  /// Bit c set when corner c of cell (i, j, k) is padding.
  [[nodiscard]] std::uint8_t padding_mask(std::size_t i, std::size_t j, std::size_t k) const;
};

/// Samples the region at every grid point (in parallel). Throws isohex::Error if the grid
/// would have more than 2^31 points.
SampledGrid sample_region(const Region& region, const DualGrid& grid);

/// What repair_manifold changed.
struct RepairCounts {
  std::size_t carved = 0;  ///< inside points made outside
  std::size_t filled = 0;  ///< outside points made inside
  std::size_t simple = 0;  ///< of those, simple points (no change of topology)
  std::size_t forced = 0;  ///< of those, edits that may change the topology
  struct Edit {
    std::size_t point;  ///< padded index
    bool simple;
  };
  std::vector<Edit> edits;  ///< every flip, in the order made (simple ones first)
  std::size_t rounds = 0;
};

/// Makes the grid manifold. First it flips only simple points (is_simple_6_18), so the
/// solid keeps the topology marching cubes gives the samples: in each non-manifold cell, a
/// corner whose flip is simple and lowers the number of non-manifold cells around it, the
/// one nearest the isosurface. What remains is forced, in two monotone phases: while some
/// cell has outside parts touching along an edge, inside points are made outside
/// (manifold_carve); then, while some cell is non-manifold, outside points are made inside
/// (manifold_fill; this can create new edge contacts, which it fills too). Each phase ends;
/// the result is the same for any thread count.
RepairCounts repair_manifold(SampledGrid& g);

/// Labels the face-connected parts of the inside points (which are the connected parts of
/// the hex mesh) and removes those with fewer than `min_points` points. Returns the numbers
/// of parts removed and kept, and of points removed.
struct ComponentCounts {
  std::size_t removed = 0, kept = 0, removed_points = 0;
};
ComponentCounts remove_small_components(SampledGrid& g, std::size_t min_points);

}  // namespace isohex::contour
