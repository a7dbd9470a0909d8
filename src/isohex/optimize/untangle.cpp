// Untangling with a regularised (ε-relaxed) barrier, after Garanzha et al. 2021.
#include "isohex/optimize/feasibility.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace isohex {

namespace {

// The smallest normalised frame determinant of each hex (+1e300 for skipped hexes), over the
// frames its energy counts, into d (sized to the hexes); with `only`, of the hexes flagged there.
void hex_min_det(const HexMesh& mesh, const std::vector<double>& inv_len, const std::vector<std::uint8_t>* skip,
                 const opt::EnergyParams& params, std::vector<double>& d, const std::vector<std::uint8_t>* only) {
  d.resize(mesh.hexes.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.hexes.size()), [&](const auto& r) {
    for (std::size_t h = r.begin(); h != r.end(); ++h) {
      if (only && !(*only)[h]) continue;
      d[h] = 1e300;
      if (skip && (*skip)[h]) continue;
      const auto p = mesh.corners(static_cast<Index>(h));
      const int frames = params.frames_of(static_cast<Index>(h));
      for (int t = 0; t < frames; ++t) d[h] = std::min(d[h], opt::frame(p, t, inv_len[h]).determinant());
      if (params.bernstein_of(static_cast<Index>(h))) {  // the coefficients the energy counts
        const std::array<double, 27> b = jacobian_bernstein(p);
        const double s = inv_len[h] * inv_len[h] * inv_len[h];
        for (double x : b) d[h] = std::min(d[h], x * s);
      }
    }
  });
}

// The hexes with a vertex that is not frozen: the only ones a sweep can change.
std::vector<std::uint8_t> touched_hexes(const HexMesh& mesh, const std::vector<std::uint8_t>& frozen) {
  std::vector<std::uint8_t> t(mesh.hexes.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.hexes.size()), [&](const auto& r) {
    for (std::size_t h = r.begin(); h != r.end(); ++h)
      for (Index v : mesh.hexes[h])
        if (!frozen[v]) t[h] = 1;
  });
  return t;
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
  const std::vector<double> sj = certified_scaled_jacobians(mesh);
  std::vector<std::uint8_t> active(mesh.points.size(), 0);
  for (Index h = 0; h < mesh.num_hexes(); ++h)
    if ((!skip || !(*skip)[h]) && (sj[h] <= 0 || is_degenerate(sj[h])))
      for (Index v : mesh.hexes[h])
        for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i)
          for (Index w : mesh.hexes[inc.ids[i]]) active[w] = 1;
  // The LP's moves are free in space: sliding boundary vertices keep to their Newton steps.
  if (surface)
    for (Index v = 0; v < mesh.num_vertices(); ++v)
      if (surface->moves_with_surface(v)) active[v] = 0;
  std::size_t moves = 0;
  for (int round = 0; round < 50; ++round) {
    const std::size_t m = opt::max_min_sweep(mesh, coloring, inc, inv_len, active, skip);
    moves += m;
    if (m == 0) break;
  }
  return moves;
}

}  // namespace

// Far-away vertices sit near their energy minimum already; sweeping them would cost most of
// the time on a large mesh with a few tangled spots.
std::vector<std::uint8_t> frozen_outside(const HexMesh& mesh, const Incidence& inc, const std::vector<double>& sj,
                                         double margin, int rings, const std::vector<std::uint8_t>* skip) {
  std::vector<std::uint8_t> active(mesh.points.size(), 0);
  // Grown ring by ring from the vertices the last ring added (those of earlier rings have
  // their neighbours in already): the set of whole-mesh passes per ring, at the cost of the rings.
  std::vector<Index> ring, next;
  for (Index h = 0; h < mesh.num_hexes(); ++h)
    if ((!skip || !(*skip)[h]) && (sj[h] < margin || is_degenerate(sj[h])))
      for (Index v : mesh.hexes[h])
        if (!active[v]) active[v] = 1, ring.push_back(v);
  for (int r = 0; r < rings && !ring.empty(); ++r) {
    next.clear();
    for (Index v : ring)
      for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i)
        for (Index w : mesh.hexes[inc.ids[i]])
          if (!active[w]) active[w] = 1, next.push_back(w);
    ring.swap(next);
  }
  for (std::uint8_t& a : active) a = !a;
  return active;
}

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
  std::vector<double> hex_eps(mesh.hexes.size(), 0.0);  // > 0: the hex is stuck, its ε frozen
  const auto finish = [&](const opt::SJStats& s) {
    res.min_sj = s.min;
    res.iterations = iterations;
    res.inverted = skipped ? opt::sj_stats(mesh).inverted : s.inverted;
    // Only the stuck hexes are measured: a whole-mesh vector here, beside the iteration's
    // per-hex arrays, was cthead h 2's peak.
    for (Index h = 0; h < mesh.num_hexes(); ++h) {
      if (!(hex_eps[h] > 0)) continue;
      const double sj = certified_scaled_jacobian(mesh.corners(h));
      if (sj <= 0 || is_degenerate(sj)) res.stuck.push_back(h);
    }
    return res;
  };

  // "Valid" means certified valid inside (certified_scaled_jacobians(): 0 for a hex whose nine
  // samples are positive but that folds inside), so the untangler works on such hexes too.
  std::vector<double> sj = certified_scaled_jacobians(mesh);
  opt::SJStats stats = opt::sj_stats_of(sj, skipped);
  if (stats.min >= options.margin) {
    res.reached_margin = true;
    res.stop = "margin";
    return finish(stats);
  }

  Incidence own_inc;
  const Incidence& inc = opt::incidence_of(mesh, options.incidence, own_inc);
  const VertexColoring coloring = color_vertices(mesh, fixed, &inc);
  const std::vector<double> inv_len = opt::inverse_edge_lengths(mesh);
  // Hexes that have not been valid inside count their interior frames too (from the first
  // time they are seen so, to the end): the 9 frames alone cannot see their fold.
  std::vector<std::uint8_t> interior(mesh.hexes.size(), 0);
  // Hexes not certified valid inside now also count det J's Bernstein coefficients: their 35
  // samples may all be positive with det J negative between them (cthead's bone at h 5 kept
  // such a pillow hex, min det J on a side face, through every round).
  std::vector<std::uint8_t> bernstein(mesh.hexes.size(), 0);
  opt::EnergyParams params{true, 1.0, options.lambda, skipped, options.surface, &hex_eps, &interior};
  params.bernstein = &bernstein;
  const std::vector<std::uint8_t> no_skip;
  const std::vector<std::uint8_t>& energy_skip = skipped ? skip : no_skip;
  // Per hex: the best (highest) smallest frame determinant seen while inverted, and when.
  std::vector<double> hex_best(mesh.hexes.size(), -1e300);
  std::vector<int> hex_gain(mesh.hexes.size(), 0);
  // Progress of the whole: fewest inverted hexes, highest smallest determinant of the hexes
  // that are neither given up nor stuck.
  std::size_t best_inverted = stats.inverted;
  double best_dmin = -1e300;
  // best_inverted and best_dmin before the first iteration and after each one.
  std::vector<std::size_t> hist_inverted{best_inverted};
  std::vector<double> hist_dmin{best_dmin};
  int since_progress = 0, rescues = 0;
  // The best state seen (fewest inverted hexes, then highest minimum): the energy is global,
  // so an iteration can trade the worst hex for the rest; a failed run must not end worse
  // than it could have.
  PointSnapshot best_points(mesh, fixed);
  opt::SJStats best = stats;
  res.stop = "max_iter";
  // Per iteration only the hexes a sweep can change (touched_hexes()) are evaluated: their
  // energies before and after it (the ε schedule's relative decrease is that of the part being
  // optimised; the rest is a constant that on cthead h 2 held σ at its floor and cost a pass
  // over every hex per iteration), then their scaled Jacobians and smallest determinants.
  std::vector<double> hex_e(mesh.hexes.size(), 0.0), hdet;
  std::vector<std::uint8_t> det_stale(mesh.hexes.size(), 1);  // hdet to recompute
  const auto sum_over = [&](const std::vector<std::uint8_t>& only) {
    double sum = 0;
    for (std::size_t h = 0; h < hex_e.size(); ++h)
      if (only[h]) sum += hex_e[h];  // in hex order: the same bits for any thread count
    return sum;
  };
  // Culling (UntangleOptions::cull): vertices that moved far last iteration, and those of hexes
  // below the margin still in the ε schedule, with the vertices of their hexes.
  const double cull = options.cull;
  std::vector<double> scale(cull > 0 ? mesh.points.size() : 0);
  for (std::size_t v = 0; v < scale.size(); ++v) scale[v] = opt::vertex_length(inc, inv_len, static_cast<Index>(v));
  std::vector<std::uint8_t> near(mesh.points.size());
  bool culling = false;  // `near` holds the last sweep's far moves
  opt::MoveRecord record{&scale, cull, std::vector<std::uint8_t>(cull > 0 ? mesh.points.size() : 0)};
  for (int it = 1; it <= options.max_iter; ++it) {
    for (std::size_t h = 0; h < sj.size(); ++h) {
      const std::uint8_t b = sj[h] <= 0 || is_degenerate(sj[h]);
      if (b != bernstein[h] || (b && !interior[h])) det_stale[h] = 1;  // the frames it counts change
      bernstein[h] = b;
      if (b) interior[h] = 1;
    }
    std::vector<std::uint8_t> frozen = frozen_outside(mesh, inc, sj, options.margin, options.rings, skipped);
    if (culling) {
      for (Index h = 0; h < mesh.num_hexes(); ++h)
        if ((!skipped || !skip[h]) && hex_eps[h] == 0 && (sj[h] < options.margin || is_degenerate(sj[h])))
          for (Index v : mesh.hexes[h])
            for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i)
              for (Index w : mesh.hexes[inc.ids[i]]) near[w] = 1;
      for (Index v = 0; v < mesh.num_vertices(); ++v) frozen[v] |= !near[v];
    }
    const std::vector<std::uint8_t> touched = touched_hexes(mesh, frozen);
    opt::hex_energies(mesh, inv_len, params, energy_skip, hex_e, &touched);  // at this ε
    const double e_before = sum_over(touched);
    std::fill(record.moved.begin(), record.moved.end(), 0);
    for (int s = 0; s < options.sweeps; ++s)
      opt::sweep(mesh, coloring, inc, inv_len, params, frozen, 2, cull > 0 ? &record : nullptr);
    res.vertex_sweeps += static_cast<std::size_t>(options.sweeps) *
                         static_cast<std::size_t>(std::count(frozen.begin(), frozen.end(), std::uint8_t{0}));
    if (cull > 0) {
      std::fill(near.begin(), near.end(), 0);
      opt::mark_far_moves(mesh, inc, record, near);
      culling = true;
    }
    opt::hex_energies(mesh, inv_len, params, energy_skip, hex_e, &touched);
    const double e_after = sum_over(touched);
    opt::update_certified_sj(mesh, touched, sj);
    for (std::size_t h = 0; h < touched.size(); ++h) det_stale[h] |= touched[h];
    stats = opt::sj_stats_of(sj, skipped);
    iterations = it;
    if (options.progress) {
      const auto n = static_cast<double>(std::count(touched.begin(), touched.end(), std::uint8_t{1}));
      options.progress({"untangle", it, n > 0 ? e_after / (9.0 * n) : 0.0, stats.min, stats.inverted});
    }
    if (stats.inverted < best.inverted || (stats.inverted == best.inverted && stats.min > best.min)) {
      best = stats;
      best_points.take(mesh);
    }
    if (stats.min >= options.margin) {
      res.reached_margin = true;
      res.stop = "margin";
      break;
    }
    // Stuck hexes: inverted, and either ε < stuck_depth·|D| (D: their smallest determinant) or
    // D has not risen by 1e-3 for `stuck_after` iterations while ε < max(|D|, stuck_eps).
    // Their ε is frozen where it is: lowering it further would make their frames (~|D|/ε² for
    // D < 0) dominate every vertex they share, crushing the valid neighbours for nothing, and
    // blow the energy up; they also leave the ε schedule. A stuck hex that becomes valid again
    // is released.
    hex_min_det(mesh, inv_len, skipped, params, hdet, &det_stale);
    std::fill(det_stale.begin(), det_stale.end(), 0);
    double dmin = 1e300;
    for (Index h = 0; h < mesh.num_hexes(); ++h) {
      if (skipped && skip[h]) continue;
      if (hdet[h] > 0) {
        hex_eps[h] = 0;
        hex_best[h] = -1e300;
      } else if (hex_eps[h] == 0 && params.eps < options.stuck_depth * -hdet[h]) {
        hex_eps[h] = params.eps;  // pressed hard (ε far below its depth) and still inverted
      } else if (hdet[h] > hex_best[h] + 1e-3 || params.eps > std::max(-hdet[h], options.stuck_eps)) {
        // Improving, or ε still above the depth of the inversion and `stuck_eps` (the energy
        // has not pressed on it hard yet): not stuck.
        hex_best[h] = hdet[h];
        hex_gain[h] = it;
      } else if (hex_eps[h] == 0 && it - hex_gain[h] >= options.stuck_after) {
        hex_eps[h] = params.eps;
      }
      if (hex_eps[h] == 0) dmin = std::min(dmin, hdet[h]);
    }
    if (dmin == 1e300) dmin = 1;  // everything left is stuck or given up
    // Stall: over the last `stall` iterations, the fewest inverted hexes fell by less than
    // `stall_fraction` (and less than 1) and the smallest determinant of the hexes not stuck
    // rose by less than 1e-3. With hexes still inverted, max–min LP moves from the best state
    // try to open the knot first; if they gain nothing, stop.
    best_inverted = std::min(best_inverted, stats.inverted);
    best_dmin = std::max(best_dmin, dmin);
    hist_inverted.push_back(best_inverted);
    hist_dmin.push_back(best_dmin);
    ++since_progress;
    if (since_progress >= options.stall) {
      // `stall` iterations ago:
      const std::size_t k = hist_inverted.size() - 1 - static_cast<std::size_t>(options.stall);
      const double then_inv = static_cast<double>(hist_inverted[k]);
      const bool fewer = static_cast<double>(best_inverted) <= then_inv - std::max(1.0, options.stall_fraction * then_inv);
      const bool higher = best_dmin >= hist_dmin[k] + 1e-3;
      if (!fewer && !higher) {
        if (stats.inverted == 0 || rescues >= options.rescues) {
          res.stop = "stall";
          break;
        }
        ++rescues;
        // From the best state: the rescue should work on the fewest inverted hexes.
        best_points.restore(mesh);
        const std::size_t moves = lp_rescue(mesh, coloring, inc, inv_len, skipped, options.surface);
        const opt::SJStats after = opt::sj_stats(mesh, skipped);
        if (options.progress) options.progress({"lp", rescues, static_cast<double>(moves), after.min, after.inverted});
        if (!(after.inverted < best.inverted || (after.inverted == best.inverted && after.min > best.min))) {
          best_points.restore(mesh);  // the rescue gained nothing
          res.stop = "stall";
          break;
        }
        res.lp_moves += moves;
        best = after;
        best_points.take(mesh);
        stats = after;
        best_inverted = std::min(best_inverted, after.inverted);
        sj = certified_scaled_jacobians(mesh);
        std::fill(det_stale.begin(), det_stale.end(), 1);  // the LP moved vertices anywhere
        culling = false;  // and the next iteration moves every vertex again
        since_progress = 0;  // a new window from here
      }
    }
    // ε update: the energy's relative decrease σ sets how far ε may drop; ε is chosen so
    // that the worst frame's χ (over the hexes neither given up nor stuck) shrinks by (1 − σ).
    const double sigma = std::max(e_before > 0 ? 1 - e_after / e_before : 0.0, options.min_decrease);
    const double mu = (1 - sigma) * chi(dmin, params.eps);
    params.eps = dmin < mu ? 2 * std::sqrt(mu * (mu - dmin)) : params.eps * (1 - sigma);
    params.eps = std::max(params.eps, 1e-12);
  }
  res.stalled = res.stop == "stall";
  if (!res.reached_margin) {
    best_points.restore(mesh);
    stats = best;
  }
  return finish(stats);
}

}  // namespace isohex
