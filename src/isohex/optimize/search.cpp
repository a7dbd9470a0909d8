// A random local search: the worst pass's last resort (search.hpp).
#include "isohex/optimize/search.hpp"

#include "isohex/optimize/feasibility.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"
#include "isohex/quality/summary.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace isohex::opt {

namespace {

// splitmix64 and Box–Muller written out: std::normal_distribution is not the same on every
// standard library, and the mesh must be.
class Random {
 public:
  explicit Random(std::uint64_t seed) : s_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  std::size_t below(std::size_t n) { return static_cast<std::size_t>(uniform() * static_cast<double>(n)); }
  Vec3 gaussian() {
    Vec3 g;
    for (int i = 0; i < 3; ++i) {
      const double u = 1.0 - uniform(), w = uniform();
      g[i] = std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * 3.14159265358979323846 * w);
    }
    return g;
  }

 private:
  std::uint64_t s_;
};

// One hex of the region: its rank now and the floors its guards hold it to.
struct HexState {
  double rank, sj_floor, ratio_floor, edge_cap;
  double held;  // a held hex: its rank when the walk began (+inf for the others)
};

// The free vertices within `rings` vertex rings of `cluster` (ring by ring, stopping before
// the ring that would pass `cap`), ascending.
std::vector<Index> region_vertices(const HexMesh& mesh, const Incidence& inc, const std::vector<std::uint8_t>& fixed,
                                   const std::vector<Index>& cluster, int rings, std::size_t cap) {
  std::vector<std::uint8_t> in(mesh.points.size(), 0);
  std::vector<Index> all, ring;
  for (Index h : cluster)
    for (Index v : mesh.hexes[h])
      if (!in[v]) in[v] = 1, ring.push_back(v);
  all = ring;
  for (int r = 0; r < rings; ++r) {
    std::vector<Index> next;
    for (Index v : ring)
      for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k)
        for (Index u : mesh.hexes[inc.ids[k]])
          if (!in[u]) in[u] = 1, next.push_back(u);
    if (all.size() + next.size() > cap) break;
    all.insert(all.end(), next.begin(), next.end());
    ring = std::move(next);
  }
  std::vector<Index> out;
  for (Index v : all)
    if (fixed.empty() || !fixed[v]) out.push_back(v);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

SearchOutcome search_region(HexMesh& mesh, const Incidence& inc, const std::vector<std::uint8_t>& fixed,
                            const std::vector<Index>& cluster, const std::vector<Vec3>& start,
                            const WorstOptions& options, double mesh_min, const std::vector<std::uint8_t>& held) {
  SearchOutcome out;
  const BoundarySurface* surface = options.surface;
  std::vector<Index> verts = region_vertices(mesh, inc, fixed, cluster, options.search_rings, options.search_vertices);
  if (surface)  // a pinned vertex, or a sliding one without a tangent plane, stays
    verts.erase(std::remove_if(verts.begin(), verts.end(),
                               [&](Index v) {
                                 Vec3 n;
                                 return surface->role(v) == BoundarySurface::Role::pinned ||
                                        (surface->role(v) == BoundarySurface::Role::slides &&
                                         !surface->tangent_normal(v, mesh.points[v], n));
                               }),
                verts.end());
  if (verts.empty()) return out;
  std::vector<Index> hexes;
  for (Index v : verts)
    for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) hexes.push_back(inc.ids[k]);
  std::sort(hexes.begin(), hexes.end());
  hexes.erase(std::unique(hexes.begin(), hexes.end()), hexes.end());
  const auto slot = [&](Index h) { return static_cast<std::size_t>(std::lower_bound(hexes.begin(), hexes.end(), h) - hexes.begin()); };
  std::vector<HexState> state;
  const double sj_level = std::max(options.sj_floor, mesh_min);
  for (Index h : hexes) {
    const auto p = mesh.corners(h);
    const CertifiedQuality c = certified_quality(p);
    const double sj = is_degenerate(c.scaled_jacobian) ? -2.0 : c.scaled_jacobian;
    const double e = edge_ratio(p);
    // The floors of the single moves, but the edge-ratio cap without their exception of 100 for
    // poor ratios: the walk moves every vertex of its region, not only those of a poor hex.
    const double r = hex_rank(c);
    state.push_back({r, std::min(sj, sj_level), std::min(c.ratio_bound, options.ratio_floor),
                     std::max(e, options.max_edge_ratio),
                     !held.empty() && held[h] ? r : std::numeric_limits<double>::infinity()});
  }
  const auto region_min = [&] {
    double m = std::numeric_limits<double>::infinity();
    for (const HexState& s : state)
      if (std::isinf(s.held)) m = std::min(m, s.rank);
    return m;
  };
  double now = out.before = out.after = region_min();
  if (!(now < kQuestionableSJ)) return out;
  std::vector<double> len;
  for (Index v : verts) len.push_back(mean_edge_at(mesh, inc, v));
  std::vector<Vec3> saved;
  for (Index v : verts) saved.push_back(mesh.points[v]);
  // The vertices of the hexes within 0.01 of the minimum: where half of the steps go.
  std::vector<std::size_t> worst;
  const auto find_worst = [&] {
    worst.clear();
    for (std::size_t s = 0; s < verts.size(); ++s)
      for (Index k = inc.offsets[verts[s]]; k < inc.offsets[verts[s] + 1]; ++k)
        if (const HexState& st = state[slot(inc.ids[k])]; std::isinf(st.held) && st.rank < now + 0.01) {
          worst.push_back(s);
          break;
        }
  };
  find_worst();
  Random rng(0x15f0e5ULL ^ static_cast<std::uint64_t>(cluster.front()));
  double sigma = 0.1;  // × the vertex's mean edge; adapted to keep about a fifth of the steps
  std::size_t window = 0, taken_in_window = 0, last_gain = 0;
  std::vector<CertifiedQuality> trial;
  for (; out.trials < options.search_trials; ++out.trials) {
    const std::size_t s = !worst.empty() && rng.uniform() < 0.5 ? worst[rng.below(worst.size())] : rng.below(verts.size());
    const Index v = verts[s];
    const Vec3 x0 = mesh.points[v];
    Vec3 d = sigma * len[s] * rng.gaussian();
    Vec3 n = Vec3::Zero();
    const bool slides = surface && surface->role(v) == BoundarySurface::Role::slides;
    if (slides && !surface->tangent_normal(v, x0, n)) continue;
    if (slides) d -= d.dot(n) * n;
    Vec3 y = x0 + d;
    bool ok = !surface || surface->put_back(v, y, n, len[s]);
    trial.clear();
    for (Index k = inc.offsets[v]; ok && k < inc.offsets[v + 1]; ++k) {
      const Index h = inc.ids[k];
      auto p = mesh.corners(h);
      for (int c = 0; c < 8; ++c) {
        if (mesh.hexes[h][c] != v) continue;
        p[c] = y;
        for (const auto& e : kHexEdges)  // the edges at v may not shrink past min_edge_shrink
          if ((e[0] == c || e[1] == c) &&
              (p[e[0]] - p[e[1]]).squaredNorm() < options.min_edge_shrink * options.min_edge_shrink *
                                                       (start[mesh.hexes[h][e[0]]] - start[mesh.hexes[h][e[1]]]).squaredNorm())
            ok = false;
      }
      const CertifiedQuality q = certified_quality(p);
      const HexState& st = state[slot(h)];
      const double sj = is_degenerate(q.scaled_jacobian) ? -2.0 : q.scaled_jacobian;
      ok = ok && hex_rank(q) >= std::min(now, st.held) && sj >= st.sj_floor && q.ratio_bound >= st.ratio_floor && edge_ratio(p) <= st.edge_cap;
      trial.push_back(q);
    }
    ++window;
    if (ok) {
      mesh.points[v] = y;
      ++out.accepted, ++taken_in_window;
      std::size_t i = 0;
      for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) state[slot(inc.ids[k])].rank = hex_rank(trial[i++]);
      if (const double m = region_min(); m > now) {
        if (m > now + 1e-4) last_gain = out.trials;
        now = m;
        find_worst();
        if (!(now < kQuestionableSJ)) break;
      }
    }
    if (window == 200) {
      const double rate = static_cast<double>(taken_in_window) / static_cast<double>(window);
      sigma = std::clamp(rate > 0.3 ? sigma * 1.5 : rate < 0.1 ? sigma * 0.7 : sigma, 1e-4, 0.3);
      window = taken_in_window = 0;
    }
    if (out.trials - last_gain > options.search_trials / 4) break;
  }
  out.after = now;
  if (!(now > out.before)) {  // a walk without a gain leaves nothing behind
    for (std::size_t s = 0; s < verts.size(); ++s) mesh.points[verts[s]] = saved[s];
    out.after = out.before;
  } else {
    out.vertices = std::move(verts);
  }
  return out;
}

}  // namespace isohex::opt
