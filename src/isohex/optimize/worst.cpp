// Worst-element pass: local max–min moves on Verdict's scaled Jacobian itself.
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/feasibility.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/summary.hpp"

#include <algorithm>
#include <numeric>

namespace isohex {

namespace {

// Degenerate (collapsed) hexes rank below every real value.
double sj_value(const std::array<Vec3, 8>& p) {
  const double v = scaled_jacobian(p);
  return is_degenerate(v) ? -2.0 : v;
}

// The lowest scaled Jacobian of the hexes around v with v placed at x. With `valid`, also
// whether every hex that is valid now (scaled Jacobian > 0) stays valid there.
double local_min(const HexMesh& mesh, const Incidence& inc, Index v, const Vec3& x, bool* valid = nullptr,
                 int* questionable = nullptr) {
  double lo = 2.0;
  if (valid) *valid = true;
  if (questionable) *questionable = 0;
  for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) {
    const Index h = inc.ids[i];
    auto p = mesh.corners(h);
    for (int k = 0; k < 8; ++k)
      if (mesh.hexes[h][k] == v) p[k] = x;
    const double q = sj_value(p);
    lo = std::min(lo, q);
    if (questionable) *questionable += q < kQuestionableSJ;
    if (valid && q <= 0 && sj_value(mesh.corners(h)) > 0) *valid = false;
  }
  return lo;
}

// One max–min move of v: a finite-difference ascent direction of the local minimum, then
// shrinking steps; the first that raises the local minimum (inverting nothing) is taken.
bool move_vertex(HexMesh& mesh, const Incidence& inc, Index v, const BoundarySurface* surface) {
  const Vec3 x0 = mesh.points[v];
  int below0 = 0;
  const double m0 = local_min(mesh, inc, v, x0, nullptr, &below0);
  const double len = opt::mean_edge_at(mesh, inc, v);
  if (!(len > 0)) return false;
  const double h = 1e-5 * len;
  Vec3 g;
  for (int j = 0; j < 3; ++j) {
    Vec3 a = x0, b = x0;
    a[j] += h;
    b[j] -= h;
    g[j] = (local_min(mesh, inc, v, a) - local_min(mesh, inc, v, b)) / (2 * h);
  }
  if (!(g.norm() > 0)) return false;
  Vec3 d = g.normalized() * len;
  // A sliding boundary vertex: tangential steps, put back on the target surface.
  const bool slides = surface && surface->role(v) == BoundarySurface::Role::slides;
  Vec3 n = Vec3::Zero();
  if (slides) {
    if (!surface->tangent_normal(v, x0, n)) return false;
    d -= n * n.dot(d);
  }
  // The best of the halving steps, not the first that gains: the first overshoots (the
  // minimum rises a hair while the other hexes around v are bent down to it), which cost the
  // ball of generate.hpp 10 % of its mean inverse mean ratio for no gain in the minimum.
  double t = 0.2, best = m0;
  Vec3 best_x = x0;
  for (int i = 0; i < 12; ++i, t *= 0.5) {
    Vec3 x = x0 + t * d;
    if (slides && !surface->reproject(v, x, n, len)) continue;  // off the surface: refused
    bool valid = false;
    int below = 0;
    // Raising the local minimum is not enough when it is negative: a valid neighbour must
    // not be inverted on the way (it could still sit above that negative minimum). Nor may
    // more hexes around v fall below 0.2: raising one by bending its neighbours down to it
    // would trade one questionable hex for several.
    const double q = local_min(mesh, inc, v, x, &valid, &below);
    if (valid && below <= below0 && q > best) {
      best = q;
      best_x = x;
    }
  }
  if (!(best > m0 + 1e-9)) return false;
  mesh.points[v] = best_x;
  return true;
}

}  // namespace

WorstResult improve_worst(HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const WorstOptions& options) {
  WorstResult res;
  const Incidence inc = vertex_hexes(mesh);
  std::vector<double> sj(mesh.hexes.size());
  for (Index h = 0; h < mesh.num_hexes(); ++h) sj[h] = sj_value(mesh.corners(h));
  const auto mesh_min = [&] { return sj.empty() ? 1.0 : *std::min_element(sj.begin(), sj.end()); };
  res.min_sj_before = res.min_sj_after = mesh_min();
  std::vector<Index> order(mesh.hexes.size());
  std::vector<Index> seen(mesh.points.size(), -1);
  for (int pass = 1; pass <= options.passes; ++pass) {
    // Sequential and in a fixed order (worst first, ties by id): deterministic, and cheap
    // since only a few hundred vertices take part.
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) { return sj[a] < sj[b]; });
    std::size_t moved = 0;
    for (std::size_t i = 0;
         i < order.size() && ((i < options.count && sj[order[i]] < options.below) || sj[order[i]] < options.raise_below);
         ++i) {
      for (Index v : mesh.hexes[order[i]]) {
        if ((!fixed.empty() && fixed[v]) || seen[v] == pass) continue;
        seen[v] = pass;
        if (!move_vertex(mesh, inc, v, options.surface)) continue;
        ++moved;
        for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) sj[inc.ids[k]] = sj_value(mesh.corners(inc.ids[k]));
      }
    }
    res.passes = pass;
    res.moves += moved;
    res.min_sj_after = mesh_min();
    if (options.progress) {
      std::size_t inverted = 0;
      for (double x : sj) inverted += x <= 0;
      options.progress({"worst", pass, static_cast<double>(moved), res.min_sj_after, inverted});
    }
    if (moved == 0) break;
  }
  return res;
}

}  // namespace isohex
