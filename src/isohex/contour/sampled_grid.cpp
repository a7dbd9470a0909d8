// The dual-contouring grid: SampledGrid's members and the sampling of the region at its points.
// The edits made to it live in manifold_repair.cpp, flip_search.cpp and grid_components.cpp.
#include "isohex/contour/sampled_grid.hpp"

#include "isohex/error.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace isohex::contour {

std::uint8_t SampledGrid::cell_mask_at(std::size_t cell) const {
  const std::size_t dy = padded[0], dz = padded[0] * padded[1];
  const std::uint8_t* p = inside.data() + cell;
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
  g.level.assign(static_cast<std::size_t>(total), 0.0f);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(1, g.padded[2] - 1), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k)
      for (std::size_t j = 1; j + 1 < g.padded[1]; ++j)
        for (std::size_t i = 1; i + 1 < g.padded[0]; ++i) {
          const Vec3 p = g.position(i, j, k);
          double l = std::numeric_limits<double>::infinity();
          for (const LevelSet& s : region.surfaces) l = std::min(l, s.level(p));
          const bool in = l > 0;  // L == 0 (and NaN) is outside
          g.inside[g.index(i, j, k)] = in;
          // Exact zeros are +0 and only they (fill_degenerate_cavities); NaN is -0.
          float lf = static_cast<float>(l);
          if (std::isnan(l)) lf = -0.0f;
          else if (l == 0) lf = 0.0f;
          else if (lf == 0.0f) lf = std::copysign(std::numeric_limits<float>::denorm_min(), static_cast<float>(l > 0 ? 1 : -1));
          g.level[g.index(i, j, k)] = lf;
        }
  });
  return g;
}

}  // namespace isohex::contour
