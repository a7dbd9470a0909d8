// Untangling with a regularised (ε-relaxed) barrier, after Garanzha et al. 2021.
#include "isohex/optimize/feasibility.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/hex_quality.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>

namespace isohex {

namespace {

// The smallest normalised frame determinant of the hexes not skipped (min is exact: thread-count
// independent).
double min_det(const HexMesh& mesh, const std::vector<double>& inv_len, const std::vector<std::uint8_t>* skip) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, mesh.hexes.size()), 1e300,
      [&](const auto& r, double lo) {
        for (std::size_t h = r.begin(); h != r.end(); ++h) {
          if (skip && (*skip)[h]) continue;
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
std::vector<std::uint8_t> frozen_outside(const HexMesh& mesh, const Incidence& inc, double margin, int rings,
                                         const std::vector<std::uint8_t>* skip) {
  const std::vector<double> sj = scaled_jacobians(mesh);
  std::vector<std::uint8_t> active(mesh.points.size(), 0);
  for (Index h = 0; h < mesh.num_hexes(); ++h)
    if ((!skip || !(*skip)[h]) && (sj[h] < margin || is_degenerate(sj[h])))
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


// Max–min LP moves on the free vertices of the inverted hexes (not given up) and their
// neighbours, for when the barrier stalls: the determinants are affine in one vertex, so each
// move is the exact best place for that vertex in the max–min sense, which the smooth energy
// (whose minimiser trades the worst frame against all the others) does not look for.
std::size_t lp_rescue(HexMesh& mesh, const VertexColoring& coloring, const Incidence& inc,
                      const std::vector<double>& inv_len, const std::vector<std::uint8_t>* skip,
                      const BoundarySurface* surface) {
  const std::vector<double> sj = scaled_jacobians(mesh);
  std::vector<std::uint8_t> active(mesh.points.size(), 0);
  for (Index h = 0; h < mesh.num_hexes(); ++h)
    if ((!skip || !(*skip)[h]) && (sj[h] <= 0 || is_degenerate(sj[h])))
      for (Index v : mesh.hexes[h])
        for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i)
          for (Index w : mesh.hexes[inc.ids[i]]) active[w] = 1;
  // The LP's moves are free in space: sliding boundary vertices keep to their Newton steps.
  if (surface)
    for (Index v = 0; v < mesh.num_vertices(); ++v)
      if (surface->role(v) == BoundarySurface::Role::slides) active[v] = 0;
  std::size_t moves = 0;
  for (int round = 0; round < 50; ++round) {
    const std::size_t m = opt::max_min_sweep(mesh, coloring, inc, inv_len, active, skip);
    moves += m;
    if (m == 0) break;
  }
  return moves;
}

}  // namespace

UntangleResult untangle(HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const UntangleOptions& options) {
  UntangleResult res;
  // Hexes that no placement of the free vertices can make valid are proven so first; one hex
  // per proof is given up (left out of the energy and the statistics) so that the untangler
  // does not crush its neighbours in vain trying, and everything else is untangled.
  if (!fixed.empty()) res.infeasible = find_infeasible(mesh, fixed);
  const std::vector<std::uint8_t> skip = opt::give_up(mesh, fixed, res.infeasible);
  for (Index h = 0; h < mesh.num_hexes(); ++h)
    if (skip[h]) res.given_up.push_back(h);
  const std::vector<std::uint8_t>* skipped = res.given_up.empty() ? nullptr : &skip;
  int iterations = 0;
  const auto finish = [&](const opt::SJStats& s) {
    res.min_sj = s.min;
    res.iterations = iterations;
    res.inverted = skipped ? opt::sj_stats(mesh).inverted : s.inverted;
    return res;
  };

  opt::SJStats stats = opt::sj_stats(mesh, skipped);
  if (stats.min >= options.margin) {
    res.reached_margin = true;
    return finish(stats);
  }

  const Incidence inc = vertex_hexes(mesh);
  const VertexColoring coloring = color_vertices(mesh, fixed);
  const std::vector<double> inv_len = opt::inverse_edge_lengths(mesh);
  opt::EnergyParams params{true, 1.0, options.lambda, skipped, options.surface};
  const std::vector<std::uint8_t> no_skip;
  const std::vector<std::uint8_t>& energy_skip = skipped ? skip : no_skip;
  double best_min = stats.min;
  int since_best = 0, rescues = 0;
  // The best state seen (fewest inverted hexes, then highest minimum): the energy is global,
  // so an iteration can trade the worst hex for the rest; a failed run must not end worse
  // than it could have.
  std::vector<Vec3> best_points = mesh.points;
  opt::SJStats best = stats;
  for (int it = 1; it <= options.max_iter; ++it) {
    const double e_before = opt::total_energy(mesh, inv_len, params, energy_skip);
    const std::vector<std::uint8_t> frozen = frozen_outside(mesh, inc, options.margin, options.rings, skipped);
    for (int s = 0; s < options.sweeps; ++s) opt::sweep(mesh, coloring, inc, inv_len, params, frozen, 2);
    const double e_after = opt::total_energy(mesh, inv_len, params, energy_skip);
    stats = opt::sj_stats(mesh, skipped);
    iterations = it;
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
    // otherwise max–min LP moves try to open the knot, and if they cannot, stop.
    if (stats.min > best_min) {
      best_min = stats.min;
      since_best = 0;
    } else if (++since_best >= (stats.inverted == 0 ? 15 : 20)) {
      if (stats.inverted == 0 || rescues >= 5) break;
      ++rescues;
      // Restart from the best state: the rescue should work on the fewest inverted hexes.
      mesh.points = best_points;
      const std::size_t moves = lp_rescue(mesh, coloring, inc, inv_len, skipped, options.surface);
      res.lp_moves += moves;
      const opt::SJStats after = opt::sj_stats(mesh, skipped);
      if (options.progress) options.progress({"lp", rescues, static_cast<double>(moves), after.min, after.inverted});
      if (after.inverted < best.inverted || (after.inverted == best.inverted && after.min > best.min)) {
        best = after;
        best_points = mesh.points;
      }
      if (moves == 0) break;
      stats = after;
      best_min = std::max(best_min, after.min);
      since_best = 0;
    }
    // ε update: the energy's relative decrease σ sets how far ε may drop; ε is chosen so
    // that the worst frame's χ shrinks by (1 − σ), which keeps it finite and the energy smooth.
    const double sigma = std::max(1 - e_after / e_before, 0.1);
    const double dmin = min_det(mesh, inv_len, skipped);
    const double mu = (1 - sigma) * chi(dmin, params.eps);
    params.eps = dmin < mu ? 2 * std::sqrt(mu * (mu - dmin)) : params.eps * (1 - sigma);
    params.eps = std::max(params.eps, 1e-12);
  }
  if (!res.reached_margin) {
    mesh.points.swap(best_points);
    stats = best;
  }
  return finish(stats);
}

}  // namespace isohex
