#pragma once
/// \file repair_internal.hpp
/// \brief Internal to the manifold repair (manifold_repair.cpp, flip_search.cpp,
/// handle_move.cpp): the helpers they share.

#include "isohex/contour/sampled_grid.hpp"
#include "isohex/contour/simple_point.hpp"

#include <array>
#include <cstddef>
#include <vector>

namespace isohex::contour {

/// The 8 cells around padded point p (never padding), by the index of their lowest corner.
inline std::array<std::size_t, 8> cells_around(const SampledGrid& g, std::size_t p) {
  const std::size_t dy = g.padded[0], dz = g.padded[0] * g.padded[1];
  std::array<std::size_t, 8> cells{};
  for (int c = 0; c < 8; ++c) cells[static_cast<std::size_t>(c)] = p - (c & 1) - dy * (c >> 1 & 1) - dz * (c >> 2 & 1);
  return cells;
}

/// True when padded point p (never padding) is simple for marching cubes' (6, 18) topology.
inline bool simple_at(const SampledGrid& g, std::size_t p) {
  const std::size_t dy = g.padded[0], dz = g.padded[0] * g.padded[1];
  Neighbourhood nb{};
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 3; ++x)
        nb[static_cast<std::size_t>(x + 3 * y + 9 * z)] = g.inside[p + x + dy * y + dz * z - 1 - dy - dz] != 0;
  return is_simple_6_18(nb);
}

/// Not padding, and next to the isosurface: some 26-neighbour was sampled on the other side
/// (flip_search.cpp).
bool near_surface(const SampledGrid& g, std::size_t p);

/// The outside samples exactly at L == 0 (SampledGrid::on_isosurface), in grid order; found per
/// z-slab in parallel. The candidates of both fills of samples at the isovalue.
std::vector<std::size_t> zero_level_outside(const SampledGrid& g);
/// The same for the samples on `side` (0 outside, 1 inside: samples at L == 0 that a repair filled).
std::vector<std::size_t> zero_level_samples(const SampledGrid& g, std::uint8_t side);

/// The non-manifold cells among `cells` and among the cells around the points flipped since
/// edit `from`, in grid order: all there are, if `cells` were all before those flips
/// (manifold_repair.cpp).
std::vector<std::size_t> still_non_manifold(const SampledGrid& g, std::vector<std::size_t> cells,
                                            const RepairCounts& counts, std::size_t from);

/// The topology-preserving phase (flip_search.cpp): each non-manifold cell in turn (`cells`,
/// all there are, in grid order) gets the best sequence of simple flips (for marching cubes'
/// (6, 18) topology) that lowers the number of non-manifold cells: short sequences in rounds
/// until one flips nothing, or one round of prepared sequences or of the deep search. That
/// number falls with every sequence, so this ends; sequential, in cell order, so it is
/// deterministic. Updates `cells` to the non-manifold cells left and returns the number of flips.
/// Where the dual vertices of several cells would go onto one sample at L == 0, makes inside
/// what puts them there, in grid order and whatever that does to the topology (there the two
/// sides touch with zero width; one point for several dual vertices is collapsed quads and
/// degenerate hexes): an outside sample at L == 0 on which more than one cell has all its
/// crossings (those fill_zero_level_samples leaves because the flip is not simple or makes a
/// cell non-manifold), and, around an inside sample at L == 0 on which more than one cell has
/// its only zeros (every outside corner of those cells carved at L > 0), those carved corners.
/// The caller then repairs the cells this makes non-manifold. Returns the samples filled
/// (kind pinch; counted in `pinch`, not yet in `filled`).
std::size_t fill_shared_pins(SampledGrid& g, RepairCounts& counts);

enum class Search { short_, prepared, deep };
std::size_t simple_phase(SampledGrid& g, RepairCounts& counts, Search mode, std::vector<std::size_t>& cells);

}  // namespace isohex::contour
