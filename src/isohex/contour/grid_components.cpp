// Edits of the grid by connected parts: the fill of zero-volume cavities (before the manifold
// repair) and the removal of small components (after it).
#include "isohex/contour/repair_internal.hpp"
#include "isohex/contour/sampled_grid.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace isohex::contour {

std::vector<std::size_t> zero_level_outside(const SampledGrid& g) { return zero_level_samples(g, 0); }

std::vector<std::size_t> zero_level_samples(const SampledGrid& g, std::uint8_t side) {
  const std::size_t dy = g.padded[0], dz = g.padded[0] * g.padded[1];
  std::vector<std::vector<std::size_t>> found(g.padded[2]);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(1, g.padded[2] - 1), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k)
      for (std::size_t p = dz * k + dy, end = dz * (k + 1) - dy; p < end; ++p)
        if (g.inside[p] == side && g.on_isosurface(p)) found[k].push_back(p);
  });
  std::vector<std::size_t> all;
  for (const auto& slab : found) all.insert(all.end(), slab.begin(), slab.end());
  return all;
}

std::size_t fill_degenerate_cavities(SampledGrid& g, RepairCounts& counts) {
  const std::size_t dy = g.padded[0], dz = g.padded[0] * g.padded[1];
  const std::vector<std::size_t> seeds = zero_level_outside(g);
  if (seeds.empty()) return 0;
  // The 18-neighbourhood: offsets with one or two nonzero coordinates.
  std::vector<std::ptrdiff_t> nb;
  for (int z = -1; z <= 1; ++z)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x) {
        const int d = (x != 0) + (y != 0) + (z != 0);
        if (d == 1 || d == 2)
          nb.push_back(x + static_cast<std::ptrdiff_t>(dy) * y + static_cast<std::ptrdiff_t>(dz) * z);
      }
  auto zero_outside = [&](std::size_t p) { return !g.inside[p] && g.on_isosurface(p); };
  std::vector<std::uint8_t> seen(g.inside.size(), 0);
  std::vector<std::size_t> part, stack;
  std::size_t cavities = 0;
  for (std::size_t seed : seeds) {
    if (seen[seed]) continue;
    // The outside part through `seed`, walked through its samples at L == 0; it is a
    // candidate while it meets no other outside sample (L < 0, NaN or padding).
    bool zero = true;
    part.assign(1, seed);
    stack.assign(1, seed);
    seen[seed] = 1;
    while (!stack.empty()) {
      const std::size_t p = stack.back();
      stack.pop_back();
      for (std::ptrdiff_t d : nb) {  // p is not padding, so its neighbours are in the array
        const std::size_t q = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(p) + d);
        if (g.inside[q]) continue;
        if (!g.on_isosurface(q)) {
          zero = false;
          continue;
        }
        if (seen[q]) continue;
        seen[q] = 1;
        part.push_back(q);
        stack.push_back(q);
      }
    }
    if (!zero) continue;
    // Zero volume: no cell has all 8 corners in the part (L == 0 throughout such a cell).
    bool flat = true;
    for (std::size_t p : part) {
      bool whole = true;
      for (int c = 0; c < 8 && whole; ++c) whole = zero_outside(g.corner_at(p, c));
      if (whole) {
        flat = false;
        break;
      }
    }
    if (!flat) continue;
    std::sort(part.begin(), part.end());
    for (std::size_t p : part) {
      g.inside[p] = 1;
      counts.edits.push_back({p, RepairKind::degenerate});
    }
    counts.filled += part.size();
    counts.degenerate += part.size();
    ++cavities;
  }
  counts.degenerate_components += cavities;
  return cavities;
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
