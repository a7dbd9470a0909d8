// Untangling with a regularised (ε-relaxed) barrier, after Garanzha et al. 2021.
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/quality/hex_quality.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>

namespace isohex {

namespace {

// The smallest normalised frame determinant of the mesh (min is exact: thread-count independent).
double min_det(const HexMesh& mesh, const std::vector<double>& inv_len) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, mesh.hexes.size()), 1e300,
      [&](const auto& r, double lo) {
        for (std::size_t h = r.begin(); h != r.end(); ++h) {
          const auto p = mesh.corners(static_cast<Index>(h));
          for (int t = 0; t < opt::kFrames; ++t) lo = std::min(lo, opt::frame(p, t, inv_len[h]).determinant());
        }
        return lo;
      },
      [](double a, double b) { return std::min(a, b); });
}

// The vertices within `rings` hex-rings of the hexes below the margin: the only ones the
// untangler moves. Far-away vertices sit near their energy minimum already; sweeping them
// would cost most of the time on a large mesh with a few tangled spots.
std::vector<std::uint8_t> frozen_outside(const HexMesh& mesh, const Incidence& inc, double margin, int rings) {
  const std::vector<double> sj = scaled_jacobians(mesh);
  std::vector<std::uint8_t> active(mesh.points.size(), 0);
  for (Index h = 0; h < mesh.num_hexes(); ++h)
    if (sj[h] < margin || is_degenerate(sj[h]))
      for (Index v : mesh.hexes[h]) active[v] = 1;
  for (int r = 0; r < rings; ++r) {
    std::vector<std::uint8_t> grown = active;
    for (Index v = 0; v < mesh.num_vertices(); ++v)
      if (active[v])
        for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i)
          for (Index w : mesh.hexes[inc.ids[i]]) grown[w] = 1;
    active.swap(grown);
  }
  for (std::uint8_t& a : active) a = !a;
  return active;
}

double chi(double D, double eps) {
  const double s = std::sqrt(eps * eps + D * D);
  return D >= 0 ? 0.5 * (D + s) : eps * eps / (2 * (s - D));
}

}  // namespace

UntangleResult untangle(HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const UntangleOptions& options) {
  UntangleResult res;
  // A hex with a corner frame that is inverted (or flat) and made of fixed vertices only
  // (e.g. all 8 fixed) cannot be repaired by moving vertices: say so up front instead of
  // deforming its neighbours in vain.
  if (!fixed.empty()) {
    for (Index h = 0; h < mesh.num_hexes(); ++h) {
      const Hex& hx = mesh.hexes[h];
      const auto p = mesh.corners(h);
      for (int t = 0; t < 8; ++t) {
        bool all_fixed = fixed[hx[t]] != 0;
        for (int j : kCornerNeighbors[t]) all_fixed = all_fixed && fixed[hx[j]];
        if (all_fixed && !(opt::frame(p, t, 1.0).determinant() > 0)) {
          res.impossible.push_back(h);
          break;
        }
      }
    }
  }
  opt::SJStats stats = opt::sj_stats(mesh);
  res.min_sj = stats.min;
  res.inverted = stats.inverted;
  if (!res.impossible.empty()) return res;
  if (stats.min >= options.margin) {
    res.reached_margin = true;
    return res;
  }

  const Incidence inc = vertex_hexes(mesh);
  const VertexColoring coloring = color_vertices(mesh, fixed);
  const std::vector<double> inv_len = opt::inverse_edge_lengths(mesh);
  opt::EnergyParams params{true, 1.0, options.lambda};
  double best_min = stats.min;
  int since_best = 0;
  // The best state seen (fewest inverted hexes, then highest minimum): the energy is global,
  // so an iteration can trade the worst hex for the rest; a failed run must not end worse
  // than it could have.
  std::vector<Vec3> best_points = mesh.points;
  opt::SJStats best = stats;
  for (int it = 1; it <= options.max_iter; ++it) {
    const double e_before = opt::total_energy(mesh, inv_len, params);
    const std::vector<std::uint8_t> frozen = frozen_outside(mesh, inc, options.margin, options.rings);
    for (int s = 0; s < options.sweeps; ++s) opt::sweep(mesh, coloring, inc, inv_len, params, frozen, 2);
    const double e_after = opt::total_energy(mesh, inv_len, params);
    stats = opt::sj_stats(mesh);
    res.iterations = it;
    if (options.progress) options.progress({"untangle", it, e_after / (9.0 * mesh.num_hexes()), stats.min, stats.inverted});
    if (stats.inverted < best.inverted || (stats.inverted == best.inverted && stats.min > best.min)) {
      best = stats;
      best_points = mesh.points;
    }
    if (stats.min >= options.margin) {
      res.reached_margin = true;
      break;
    }
    // No progress on the worst element for a while: with nothing inverted the margin is out
    // of reach with these fixed vertices (the shape stages take over from a valid mesh);
    // otherwise, after a longer wait, the fixed vertices likely leave no valid placement.
    if (stats.min > best_min) {
      best_min = stats.min;
      since_best = 0;
    } else if (++since_best >= (stats.inverted == 0 ? 15 : 40)) {
      break;
    }
    // ε update: the energy's relative decrease σ sets how far ε may drop; ε is chosen so
    // that the worst frame's χ shrinks by (1 − σ), which keeps it finite and the energy smooth.
    const double sigma = std::max(1 - e_after / e_before, 0.1);
    const double dmin = min_det(mesh, inv_len);
    const double mu = (1 - sigma) * chi(dmin, params.eps);
    params.eps = dmin < mu ? 2 * std::sqrt(mu * (mu - dmin)) : params.eps * (1 - sigma);
    params.eps = std::max(params.eps, 1e-12);
  }
  if (!res.reached_margin) {
    mesh.points.swap(best_points);
    stats = best;
  }
  res.min_sj = stats.min;
  res.inverted = stats.inverted;
  return res;
}

}  // namespace isohex
