#include "isohex/contour/sampled_grid.hpp"

#include "isohex/contour/cell_cases.hpp"
#include "isohex/error.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace isohex::contour {

std::uint8_t SampledGrid::cell_mask(std::size_t i, std::size_t j, std::size_t k) const {
  const std::size_t base = index(i, j, k), dy = padded[0], dz = padded[0] * padded[1];
  const std::uint8_t* p = inside.data() + base;
  return static_cast<std::uint8_t>(p[0] | p[1] << 1 | p[dy] << 2 | p[dy + 1] << 3 | p[dz] << 4 | p[dz + 1] << 5 |
                                   p[dz + dy] << 6 | p[dz + dy + 1] << 7);
}

std::uint8_t SampledGrid::padding_mask(std::size_t i, std::size_t j, std::size_t k) const {
  std::uint8_t m = 0;
  for (int c = 0; c < 8; ++c)
    if (is_padding(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1))) m |= static_cast<std::uint8_t>(1u << c);
  return m;
}

SampledGrid sample_region(const Region& region, const DualGrid& grid) {
  SampledGrid g;
  g.grid = grid;
  g.domain = region.domain;
  double total = 1;
  for (int a = 0; a < 3; ++a) {
    g.padded[a] = static_cast<std::size_t>(grid.points[a]) + 2;
    total *= static_cast<double>(g.padded[a]);
  }
  if (total > static_cast<double>(std::numeric_limits<Index>::max()))
    throw Error(fmt::format("a grid of {} x {} x {} points is too large (over 2^31 points); use a larger cell size",
                            grid.points[0], grid.points[1], grid.points[2]));
  g.inside.assign(static_cast<std::size_t>(total), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(1, g.padded[2] - 1), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k)
      for (std::size_t j = 1; j + 1 < g.padded[1]; ++j)
        for (std::size_t i = 1; i + 1 < g.padded[0]; ++i) {
          const Vec3 p = g.position(i, j, k);
          bool in = true;
          for (const LevelSet& s : region.surfaces)
            if (!(s.level(p) > 0)) {  // L == 0 (and NaN) is outside
              in = false;
              break;
            }
          g.inside[g.index(i, j, k)] = in;
        }
  });
  return g;
}

std::size_t repair_manifold(SampledGrid& g, std::size_t* rounds) {
  const std::size_t nk = g.num_cells(2);
  // Slabs of cells to (re)check: all at first, then those around the points just filled.
  std::vector<std::uint8_t> dirty(nk, 1);
  std::vector<std::vector<std::size_t>> fills(nk);
  std::size_t added = 0, round = 0;
  for (;; ++round) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nk), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t k = r.begin(); k != r.end(); ++k) {
        fills[k].clear();
        if (!dirty[k]) continue;
        for (std::size_t j = 0; j < g.num_cells(1); ++j)
          for (std::size_t i = 0; i < g.num_cells(0); ++i) {
            const std::uint8_t m = g.cell_mask(i, j, k);
            if (cell_case(m).manifold) continue;
            const std::uint8_t f = manifold_fill(m, g.padding_mask(i, j, k));
            for (int c = 0; c < 8; ++c)
              if (f & (1u << c)) fills[k].push_back(g.index(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1)));
          }
      }
    });
    std::fill(dirty.begin(), dirty.end(), 0);
    std::size_t changed = 0;
    const std::size_t plane = g.padded[0] * g.padded[1];
    for (const auto& slab : fills)
      for (std::size_t p : slab) {
        if (g.inside[p]) continue;  // two cells asked for the same point
        g.inside[p] = 1;
        ++changed;
        const std::size_t pk = p / plane;  // the point touches cell slabs pk - 1 and pk
        if (pk > 0) dirty[pk - 1] = 1;
        if (pk < nk) dirty[pk] = 1;
      }
    added += changed;
    if (changed == 0) break;
  }
  if (rounds) *rounds = round + 1;
  return added;
}

ComponentCounts remove_small_components(SampledGrid& g, std::size_t min_points) {
  ComponentCounts counts;
  // Sequential flood fill: labels depend only on the grid, and it is cheap next to sampling.
  std::vector<std::int32_t> label(g.inside.size(), -1);
  std::vector<std::size_t> sizes, stack;
  const std::size_t steps[3] = {1, g.padded[0], g.padded[0] * g.padded[1]};
  for (std::size_t seed = 0; seed < g.inside.size(); ++seed) {
    if (!g.inside[seed] || label[seed] >= 0) continue;
    const auto id = static_cast<std::int32_t>(sizes.size());
    std::size_t n = 0;
    label[seed] = id;
    stack.push_back(seed);
    while (!stack.empty()) {
      const std::size_t p = stack.back();
      stack.pop_back();
      ++n;
      // Inside points are never padding, so p ± step stays in the array.
      for (std::size_t s : steps)
        for (std::size_t q : {p - s, p + s})
          if (g.inside[q] && label[q] < 0) {
            label[q] = id;
            stack.push_back(q);
          }
    }
    sizes.push_back(n);
  }
  for (std::size_t n : sizes) {
    if (n < min_points) {
      ++counts.removed;
      counts.removed_points += n;
    } else {
      ++counts.kept;
    }
  }
  if (counts.removed)
    for (std::size_t p = 0; p < g.inside.size(); ++p)
      if (g.inside[p] && sizes[static_cast<std::size_t>(label[p])] < min_points) g.inside[p] = 0;
  return counts;
}

}  // namespace isohex::contour
