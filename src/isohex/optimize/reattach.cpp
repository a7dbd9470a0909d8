// Released boundary vertices back onto their surface after optimisation.
#include "isohex/optimize/feasibility.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/jacobian_bounds.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace isohex {

ReattachResult reattach_released(HexMesh& mesh, BoundarySurface& surface, const ReattachOptions& options) {
  ReattachResult res;
  res.loose_before = surface.num_loose();
  if (res.loose_before == 0) return res;
  const Incidence inc = vertex_hexes(mesh);
  std::vector<double> rank(mesh.hexes.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rank.size(), 1024), [&](const auto& r) {
    for (std::size_t h = r.begin(); h != r.end(); ++h) rank[h] = opt::hex_rank(certified_quality(mesh.corners(static_cast<Index>(h))));
  });
  const double floor = std::max(options.floor, rank.empty() ? 1.0 : *std::min_element(rank.begin(), rank.end()));
  std::vector<double> ranks;
  for (int round = 0; round < options.rounds; ++round) {
    std::size_t n = 0;
    for (Index v = 0; v < mesh.num_vertices(); ++v) {
      if (surface.role(v) != BoundarySurface::Role::loose) continue;
      Vec3 x = mesh.points[v];
      if (!surface.snap(v, x, opt::mean_edge_at(mesh, inc, v))) continue;
      ranks.clear();
      bool ok = true;
      for (Index i = inc.offsets[v]; ok && i < inc.offsets[v + 1]; ++i) {
        const Index h = inc.ids[i];
        ranks.push_back(opt::hex_rank(certified_quality(opt::corners_with(mesh, h, v, x))));
        ok = ranks.back() >= std::min(rank[h], floor);
      }
      if (!ok || !surface.reattach(v)) continue;
      mesh.points[v] = x;
      for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) rank[inc.ids[i]] = ranks[static_cast<std::size_t>(i - inc.offsets[v])];
      ++n;
    }
    res.reattached += n;
    if (n == 0) break;
  }
  return res;
}

}  // namespace isohex
