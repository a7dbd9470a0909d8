// Carving of filaments thinner than a fraction of a cell (sampled_grid.hpp).
#include "isohex/contour/repair_internal.hpp"

#include <algorithm>
#include <cstddef>
#include <vector>

namespace isohex::contour {

namespace {

// The sample's tests of carve_thin_features.
bool thin_tip(const SampledGrid& g, std::size_t p, double max_fraction) {
  if (!g.inside[p] || g.is_padding_at(p)) return false;
  const std::size_t step[3] = {1, g.padded[0], g.padded[0] * g.padded[1]};
  int bounded = 0;
  bool face_neighbour = false;
  double nearest = 2;
  const double l = g.level[p];
  for (const std::size_t s : step) {
    const std::size_t q[2] = {p - s, p + s};
    bool both = true;
    for (const std::size_t n : q) {
      if (g.inside[n]) {
        both = false;
        face_neighbour = true;
        continue;
      }
      const double ln = g.level[n];
      if (!g.is_padding_at(n) && ln <= 0 && l > 0) nearest = std::min(nearest, l / (l - ln));
    }
    bounded += both;
  }
  if (bounded < 2 || !(nearest < max_fraction)) return false;
  return !face_neighbour || simple_at(g, p);
}

}  // namespace

std::size_t carve_thin_features(SampledGrid& g, double max_fraction, RepairCounts& counts) {
  if (!(max_fraction > 0)) return 0;
  const std::size_t dy = g.padded[0], dz = g.padded[0] * g.padded[1];
  std::vector<std::size_t> todo;
  for (std::size_t p = 0; p < g.inside.size(); ++p)
    if (thin_tip(g, p, max_fraction)) todo.push_back(p);
  std::size_t carved = 0;
  // Each round takes its candidates in grid order; a carve makes its inside face neighbours
  // candidates of the next round (the next sample of the filament is now its tip).
  while (!todo.empty()) {
    std::vector<std::size_t> next;
    for (const std::size_t p : todo) {
      if (!thin_tip(g, p, max_fraction)) continue;
      g.inside[p] = 0;
      counts.edits.push_back({p, RepairKind::thin});
      ++carved;
      for (const std::size_t n : {p - 1, p + 1, p - dy, p + dy, p - dz, p + dz})
        if (g.inside[n]) next.push_back(n);
    }
    std::sort(next.begin(), next.end());
    next.erase(std::unique(next.begin(), next.end()), next.end());
    todo = std::move(next);
  }
  counts.carved += carved;
  counts.thin += carved;
  return carved;
}

}  // namespace isohex::contour
