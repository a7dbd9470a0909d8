// Worst-element pass: local max–min moves on Verdict's scaled Jacobian itself.
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/feasibility.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/patch.hpp"
#include "isohex/optimize/search.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"
#include "isohex/quality/summary.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace isohex {

namespace {

// Degenerate (collapsed) hexes rank below every real value; a hex that is not certified valid
// inside counts as 0 at best, whatever its nine samples say.
double sj_value(const std::array<Vec3, 8>& p) {
  const double v = certified_scaled_jacobian(p);
  return is_degenerate(v) ? -2.0 : v;
}

// The vertices of the lowest of a hex's nine scaled-Jacobian frames: a corner and its three
// neighbours, or all eight for the centre frame.
std::vector<Index> worst_frame_vertices(const std::array<Vec3, 8>& p, const Hex& hex) {
  int worst = 0;
  double lo = std::numeric_limits<double>::infinity();
  for (int t = 0; t < opt::kFrames; ++t)
    if (const double v = opt::scaled_frame_value(p, t); v < lo) lo = v, worst = t;
  if (worst == opt::kCentreFrame) return {hex.begin(), hex.end()};
  const auto& n = kCornerNeighbors[worst];
  return {hex[worst], hex[n[0]], hex[n[1]], hex[n[2]]};
}

// The vertices of `hexes` that are not fixed (ascending).
std::vector<Index> free_vertices(const HexMesh& mesh, const std::vector<std::uint8_t>& fixed,
                                 const std::vector<Index>& hexes) {
  std::vector<Index> p;
  for (Index h : hexes)
    for (Index v : mesh.hexes[h])
      if (fixed.empty() || !fixed[v]) p.push_back(v);
  std::sort(p.begin(), p.end());
  p.erase(std::unique(p.begin(), p.end()), p.end());
  return p;
}

// The hexes around the free vertices of hex h's worst frame: where that frame's one free vertex
// cannot turn without folding a corner of the next hex, that hex's other vertices must make room
// (ECR block_in with its boundary fixed: a corner of two fixed boundary edges that can reach
// 0.2026 at best stayed at 0.199, its free edge's turn taking a corner of the next hex from 0.27
// to 0.04).
std::vector<Index> frame_star(const HexMesh& mesh, const Incidence& inc, const std::vector<std::uint8_t>& fixed, Index h) {
  std::vector<Index> around;
  for (Index v : worst_frame_vertices(mesh.corners(h), mesh.hexes[h]))
    if (fixed.empty() || !fixed[v])
      for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) around.push_back(inc.ids[k]);
  return around;
}

// The lowest scaled Jacobian of the hexes around v with v placed at x. With `valid`, also
// whether every hex that is valid now (scaled Jacobian > 0) stays valid there and no edge at
// v is shorter than `shrink` times its length in `start` (the mesh when the pass began): the
// scaled Jacobian is blind to edge lengths, so a max–min ascent alone may shrink an edge
// towards zero (on a sphere's mesh it drove the mean inverse mean ratio from 1.3 to 81).
// With `ratio`, also the smallest jacobian_ratio_bound() of those hexes: the scaled Jacobian
// samples det J at nine points, so the pass must not buy them with a distorted interior.
// With `edges`, also the largest edge ratio of those hexes.
double local_min(const HexMesh& mesh, const Incidence& inc, Index v, const Vec3& x, bool* valid = nullptr,
                 int* questionable = nullptr, const std::vector<Vec3>* start = nullptr, double shrink = 0,
                 double* ratio = nullptr, double* edges = nullptr) {
  double lo = 2.0;
  if (valid) *valid = true;
  if (questionable) *questionable = 0;
  if (ratio) *ratio = 1.0;
  if (edges) *edges = 1.0;
  for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) {
    const Index h = inc.ids[i];
    const auto p = opt::corners_with(mesh, h, v, x);
    double q;
    if (ratio) {  // both from one evaluation of the hex's Bernstein coefficients
      const CertifiedQuality c = certified_quality(p);
      q = is_degenerate(c.scaled_jacobian) ? -2.0 : c.scaled_jacobian;
      *ratio = std::min(*ratio, c.ratio_bound);
    } else {
      q = sj_value(p);
    }
    lo = std::min(lo, q);
    if (questionable) *questionable += q < kQuestionableSJ;
    if (edges) *edges = std::max(*edges, edge_ratio(p));  // Verdict's, as `isohex quality` reports it
    if (!valid) continue;
    if (q <= 0 && sj_value(mesh.corners(h)) > 0) *valid = false;
    for (const auto& e : kHexEdges) {
      const Index a = mesh.hexes[h][e[0]], b = mesh.hexes[h][e[1]];
      if (start && (a == v || b == v) &&
          (p[e[0]] - p[e[1]]).squaredNorm() < shrink * shrink * ((*start)[a] - (*start)[b]).squaredNorm())
        *valid = false;
    }
  }
  return lo;
}

using opt::kRatioWeight;

// The largest Bernstein coefficient of det J of each hex around v as the mesh stands (in
// incidence order; 0 for a hex with none positive): the ratio terms' constant normalisation
// during one move of v.
std::vector<double> ratio_norms(const HexMesh& mesh, const Incidence& inc, Index v) {
  std::vector<double> m;
  for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) m.push_back(opt::bernstein_norm(mesh.corners(inc.ids[i])));
  return m;
}

// The Bernstein coefficients of det J of each hex around v over its norm, as affine functions
// of v's place (opt::ratio_coefficients). Their minimum bounds the hex's jacobian ratio from
// below, so a max–min move on them raises the element's interior, not only Verdict's nine
// samples.
void ratio_terms(const HexMesh& mesh, const Incidence& inc, Index v, const Vec3& x, bool value_only,
                 const std::vector<double>& norms, std::vector<opt::Affine>& out) {
  std::array<double, 27> b;
  std::array<std::array<Vec3, 27>, 8> g;
  for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) {
    const double m = norms[static_cast<std::size_t>(i - inc.offsets[v])];
    if (!(m > 0)) continue;
    const Index h = inc.ids[i];
    auto p = mesh.corners(h);
    int k = 0;
    while (mesh.hexes[h][k] != v) ++k;
    p[k] = x;
    std::array<bool, 8> corner{};
    corner[k] = true;
    opt::ratio_coefficients(p, kRatioWeight, m, corner, b, value_only ? nullptr : &g);
    for (int n = 0; n < 27; ++n) out.push_back({value_only ? Vec3::Zero() : g[k][n], b[n]});
  }
}

// The scaled Jacobians of the frames (of the hexes around v) that v's position changes, each
// as its value and gradient in that position (opt::scaled_frame). Verdict's hex value is the
// minimum of these and of the frames v is not in. With `value_only`, the gradients are left
// zero; with `norms` (ratio_norms()), ratio_terms() come too.
std::vector<opt::Affine> frame_values(const HexMesh& mesh, const Incidence& inc, Index v, const Vec3& x,
                                      bool value_only, const std::vector<double>* norms) {
  std::vector<opt::Affine> out;
  if (norms) ratio_terms(mesh, inc, v, x, value_only, *norms, out);
  for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) {
    const Index h = inc.ids[i];
    auto p = mesh.corners(h);
    int k = 0;
    while (mesh.hexes[h][k] != v) ++k;
    p[k] = x;
    for (int t = 0; t < opt::kFrames; ++t) {
      const Vec3& c = opt::frame_coefficient(t, k);
      if (!c.isZero()) out.push_back(opt::scaled_frame(opt::frame(p, t, 1.0), c, value_only));
    }
  }
  return out;
}

double lowest(const std::vector<opt::Affine>& f) {
  double lo = 2.0;
  for (const opt::Affine& a : f) lo = std::min(lo, a.b);
  return lo;
}

// A max–min move of v: at its current place, the frame values v changes are linearised and
// the LP max_min_affine() finds the step within a trust box that maximises their smallest
// (a first-order model of a nonsmooth max–min, which a single gradient misses where two
// frames tie: following either one lowers the other). The box halves until the true values
// confirm a gain, and the model is rebuilt at the new place a few times. A step is taken only
// if the smallest of those frame values rises, Verdict's minimum around v does not fall, no
// valid hex is inverted and no more hexes around v fall below 0.2; so the mesh minimum never
// falls. A sliding vertex steps in its tangent plane and is put back on its surface.
//
// With the ratio terms, the smallest value is often a ratio term that no move of v alone can
// raise (a cluster of pillow hexes with ratios 0.07-0.08 at a convex tip of cthead h 4), and a
// scaled Jacobian below 0.2 beside it was left as it was. A second phase then raises the
// scaled-Jacobian frames alone with the ratio terms held as constraints: none falls below the
// smallest of them now, and the certified ratio around v does not fall either.
bool move_vertex(HexMesh& mesh, const Incidence& inc, Index v, const std::vector<Vec3>& start,
                 const BoundarySurface* surface, const WorstOptions& options, double mesh_min) {
  const Vec3 x0 = mesh.points[v];
  int below0 = 0;
  double ratio0 = 1;
  double edges0 = 1;
  const double m0 = local_min(mesh, inc, v, x0, nullptr, &below0, nullptr, 0, &ratio0, &edges0);
  // Raising a ratio below the floor (0.1) outranks the edge-ratio aim: such a vertex may go
  // up to the limit instead.
  const double edge_cap =
      std::max(edges0, options.ratio_terms && ratio0 < kPoorJacobianRatio ? options.poor_ratio_edge_limit
                                                                          : options.max_edge_ratio);
  const double ratio_floor = std::min(ratio0, options.ratio_floor);
  // With the ratio terms, the scaled Jacobian around v may fall to buy a ratio, but not below
  // the higher of sj_floor and the mesh minimum (so that never falls); without them it holds.
  const double sj_floor = options.ratio_terms ? std::min(m0, std::max(options.sj_floor, mesh_min)) : m0;
  const std::vector<double> norms = options.ratio_terms ? ratio_norms(mesh, inc, v) : std::vector<double>{};
  const std::vector<double>* ratio = options.ratio_terms ? &norms : nullptr;
  const double len = opt::mean_edge_at(mesh, inc, v);
  if (!(len > 0)) return false;
  const bool slides = surface && surface->role(v) == BoundarySurface::Role::slides;
  Vec3 x = x0;
  bool moved = false;
  // Phase 2's constraint level: the smallest ratio term where it starts (NaN in phase 1).
  double held_ratio = std::numeric_limits<double>::quiet_NaN();
  // The terms of the model at y: the frames (and in phase 1 the ratio terms) to raise, as
  // weight-1 terms; in phase 2 the ratio terms as constraints, offset by held_ratio and
  // weighted almost 0 (f >= s·w is then f >= held_ratio, nearly).
  struct Model {
    std::vector<opt::Affine> f;
    std::vector<double> w;
    double now;          // the smallest term to raise
    std::size_t raised;  // the terms to raise come first; the constraints follow them
  };
  const auto terms = [&](const Vec3& y, bool value_only) {
    Model m{frame_values(mesh, inc, v, y, value_only, std::isnan(held_ratio) ? ratio : nullptr), {}, 0, 0};
    m.now = lowest(m.f);
    m.raised = m.f.size();
    m.w.assign(m.f.size(), 1.0);
    if (!std::isnan(held_ratio)) {
      std::vector<opt::Affine> r;
      ratio_terms(mesh, inc, v, y, value_only, norms, r);
      for (opt::Affine& a : r) a.b -= held_ratio, m.f.push_back(a), m.w.push_back(1e-6);
    }
    return m;
  };
  for (int phase = 1; phase <= (options.ratio_terms ? 2 : 1); ++phase) {
    if (phase == 2) {
      std::vector<opt::Affine> r;
      ratio_terms(mesh, inc, v, x, true, norms, r);
      if (r.empty()) break;
      held_ratio = lowest(r);
    }
    double box = options.step * len;
    for (int model = 0; model < options.models; ++model) {
      Model m = terms(x, false);
      std::vector<opt::Affine>& f = m.f;
      std::vector<double>& w = m.w;
      const double now = m.now;
      // Frames at the target are good enough: no move there, and the model seeks no more (a
      // constant frame at the target caps the LP's bound), so the max–min step does not flatten
      // the shape of hexes that need no help.
      if (!(now < options.target)) break;
      // Tangential steps of a sliding vertex: the LP's unknowns are coordinates in the tangent
      // plane (the third has no effect and stays in the box).
      Vec3 n = Vec3::Zero(), t1 = Vec3::UnitX(), t2 = Vec3::UnitY();
      if (slides) {
        if (!surface->tangent_normal(v, x, n)) break;
        t1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
        t2 = n.cross(t1);
        for (opt::Affine& a : f) a.a = Vec3(a.a.dot(t1), a.a.dot(t2), 0.0);
      }
      f.push_back({Vec3::Zero(), options.target});
      w.push_back(1.0);
      bool gained = false;
      for (int trial = 0; trial < options.trials && !gained; ++trial, box *= 0.5) {
        const opt::MaxMin r = opt::max_min_affine(f, w, box);
        if (!r.ok || !(r.s > now + 1e-9)) break;  // no ascent even in the model: a max–min point
        Vec3 y = slides ? Vec3(x + r.d[0] * t1 + r.d[1] * t2) : Vec3(x + r.d);
        if (surface && !surface->put_back(v, y, n, len)) continue;  // off the surface (or band): refused
        bool valid = false;
        int below = 0;
        double ratio_y = 1, edges_y = 1;
        // A negative local minimum may rise while a valid neighbour is inverted on the way;
        // raising one hex by bending several others below 0.2 is no gain.
        const double q =
            local_min(mesh, inc, v, y, &valid, &below, &start, options.min_edge_shrink, &ratio_y, &edges_y);
        if (!valid || below > below0 || q < sj_floor || ratio_y < ratio_floor || edges_y > edge_cap) continue;
        const Model my = terms(y, true);
        if (!(my.now > now + 1e-9)) continue;
        // Phase 2: the ratio terms held, and the certified ratio around v too; the scaled
        // Jacobian it raises may not fall.
        if (phase == 2 && (ratio_y < ratio0 || q < m0 || std::any_of(my.f.begin() + static_cast<std::ptrdiff_t>(my.raised), my.f.end(),
                                                           [](const opt::Affine& a) { return a.b < 0; })))
          continue;
        x = y;
        gained = moved = true;
      }
      if (!gained) break;
      box = std::min(4 * box, options.step * len);  // the box that worked, doubled (the loop halved it once more)
    }
  }
  if (!moved) return false;
  mesh.points[v] = x;
  return true;
}

}  // namespace

WorstResult improve_worst(HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const WorstOptions& options) {
  WorstResult res;
  Incidence own_inc;
  const Incidence& inc = opt::incidence_of(mesh, options.incidence, own_inc);
  std::vector<double> sj(mesh.hexes.size());
  // The pass works on the hexes lowest in `rank`: the scaled Jacobian, or with ratio_terms the
  // lower of it and the hex's Bernstein ratio bound.
  std::vector<double> rank(mesh.hexes.size());
  const auto update = [&](Index h) {
    const auto p = mesh.corners(h);
    if (!options.ratio_terms) {
      sj[h] = rank[h] = sj_value(p);
      return;
    }
    const CertifiedQuality c = certified_quality(p);
    sj[h] = is_degenerate(c.scaled_jacobian) ? -2.0 : c.scaled_jacobian;
    rank[h] = opt::hex_rank(c);
  };
  tbb::parallel_for(tbb::blocked_range<Index>(0, mesh.num_hexes(), 1024), [&](const tbb::blocked_range<Index>& r) {
    for (Index h = r.begin(); h != r.end(); ++h) update(h);  // each hex its own entries
  });
  const auto mesh_min = [&] { return sj.empty() ? 1.0 : *std::min_element(sj.begin(), sj.end()); };
  res.min_sj_before = res.min_sj_after = mesh_min();
  std::vector<Index> order;
  std::vector<Index> seen(mesh.points.size(), -1);
  const std::vector<Vec3> start = mesh.points;
  // A fixed order: worst first by the ranks at the time of sorting, ties by id. The loops read
  // it while moves change ranks, so how far they go is open; it is sorted lazily instead
  // (on cthead h 2 a full sort of 585,000 hexes per pass took about a fifth of the passes'
  // time): first the hexes below max(0.2, raise_below) and at least the `count` lowest, then
  // more on demand (has()), in the same order as a full sort.
  const double needed_below = std::max(options.raise_below, kQuestionableSJ);
  std::vector<double> sorted_rank;  // the ranks `order` is sorted by
  std::vector<Index> unsorted;      // the hexes not in `order` yet
  const auto worse = [&](Index a, Index b) {
    return sorted_rank[a] < sorted_rank[b] || (sorted_rank[a] == sorted_rank[b] && a < b);
  };
  const auto take = [&](std::size_t k) {  // the k worst of `unsorted`, appended in order
    k = std::min(k, unsorted.size());
    const auto mid = unsorted.begin() + static_cast<std::ptrdiff_t>(k);
    if (mid != unsorted.end()) std::nth_element(unsorted.begin(), mid, unsorted.end(), worse);
    std::sort(unsorted.begin(), mid, worse);
    order.insert(order.end(), unsorted.begin(), mid);
    unsorted.erase(unsorted.begin(), mid);
  };
  const auto has = [&](std::size_t i) {  // order[i] exists (sorted further if needed)
    if (i >= order.size() && !unsorted.empty()) take(std::max<std::size_t>(i + 1 - order.size(), order.size()));
    return i < order.size();
  };
  const auto sort_worst_first = [&] {
    sorted_rank = rank;
    order.clear();
    unsorted.clear();
    for (Index h = 0; h < mesh.num_hexes(); ++h) (rank[h] < needed_below ? order : unsorted).push_back(h);
    std::sort(order.begin(), order.end(), worse);
    has(std::max<std::size_t>(options.count, 1) - 1);  // standing() reads them
  };
  int pass = 0;
  // What a pass is judged by, read off `order` (sorted worst first): the lowest rank, the
  // deficit of the hexes below 0.2 by rank (the sum of their distances to 0.2), and the mean of
  // the `count` lowest ranks (the tail it raises once none is below 0.2).
  struct Standing {
    double min = 2, deficit = 0, tail = 0;
  };
  const auto standing = [&] {
    Standing s;
    const std::size_t k = std::min(std::max<std::size_t>(options.count, 1), order.size());
    if (k == 0) return s;
    s.min = rank[order[0]];
    for (std::size_t i = 0; i < k; ++i) s.tail += rank[order[i]] / static_cast<double>(k);
    for (std::size_t i = 0; has(i) && rank[order[i]] < kQuestionableSJ; ++i)
      s.deficit += kQuestionableSJ - rank[order[i]];
    return s;
  };
  // A vertex whose move found no gain is not tried again until a vertex of a hex around it
  // moves (in a pass, a joint move or a walk) or the floor the move reads from the mesh
  // minimum changes: move_vertex() reads nothing else, so skipping it gives the same mesh.
  // (Trying every vertex again at each new minimum and after each joint move was half of
  // cthead h 2's 200,000 tries, 94 us each.)
  std::vector<std::uint8_t> settled(mesh.points.size(), 0);
  std::vector<double> settled_at(mesh.points.size(), 0);
  // When each vertex last moved, on a clock of moves (for the joint moves' memo below).
  std::vector<std::uint64_t> moved_at(mesh.points.size(), 0);
  std::uint64_t clock = 0;
  const auto unsettle_around = [&](Index v) {
    moved_at[v] = ++clock;
    for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k)
      for (Index w : mesh.hexes[inc.ids[k]]) settled[w] = 0;
  };
  // What move_vertex() reads of the mesh minimum: its scaled-Jacobian floor with the ratio
  // terms, nothing without them.
  const auto floor_of = [&](double min_now) { return options.ratio_terms ? std::max(options.sj_floor, min_now) : 0.0; };
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  const auto untimed_passes = [&](int passes, int stall_passes) {
    std::vector<Standing> history;
    for (int end = pass + passes; pass < end;) {
      sort_worst_first();
      // A stall: tiny gains go on for ever (a move is kept for any rise of its own
      // minimum), so the passes stop once `stall_passes` of them together gained little by
      // the standing: the minimum, and the deficit below 0.2 while there is one, else the
      // tail (cthead h 4: 100 passes at a minimum of 0.163 that only the walk raised; with the
      // minimum alone, pave1 fixed ended at 0.303 instead of 0.403).
      history.push_back(standing());
      if (stall_passes > 0 && history.size() > static_cast<std::size_t>(stall_passes)) {
        const Standing& then = history[history.size() - 1 - static_cast<std::size_t>(stall_passes)];
        const Standing& now = history.back();
        const bool stalled = then.deficit > 0 ? now.deficit >= (1 - options.stall_fraction) * then.deficit
                                              : now.tail < then.tail + options.stall_gain;
        if (stalled && now.min < then.min + options.stall_gain) break;
      }
      // Sequential: deterministic, and cheap since only a few hundred vertices take part.
      ++pass;
      std::size_t moved = 0;
      const double min_now = mesh_min(), floor_now = floor_of(min_now);
      for (std::size_t i = 0;
           has(i) && ((i < options.count && rank[order[i]] < options.below) || rank[order[i]] < options.raise_below);
           ++i) {
        for (Index v : mesh.hexes[order[i]]) {
          if ((!fixed.empty() && fixed[v]) || seen[v] == pass) continue;
          seen[v] = pass;
          if (settled[v] && settled_at[v] == floor_now) continue;
          if (!move_vertex(mesh, inc, v, start, options.surface, options, min_now)) {
            settled[v] = 1, settled_at[v] = floor_now;
            continue;
          }
          unsettle_around(v);
          ++moved;
          for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) update(inc.ids[k]);
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
  };
  const auto single_passes = [&](int passes, int stall_passes) {
    const auto t0 = Clock::now();
    untimed_passes(passes, stall_passes);
    res.passes_seconds += since(t0);
  };
  single_passes(options.passes, options.stall_passes);
  // The end game: each cluster of hexes still below 0.2 by rank with the free vertices of its
  // hexes moved together, or where that gains nothing those of its worst hex (or of the hexes
  // around its worst frame); the single moves again after a round that moved something.
  const auto free_vertices_of = [&](const std::vector<Index>& hexes) { return free_vertices(mesh, fixed, hexes); };
  // The hexes below 0.2 by rank that share a vertex with h, and so on (ascending): a cluster of
  // poor hexes at one bad spot of the boundary tie with each other.
  std::vector<std::uint8_t> clustered(mesh.hexes.size(), 0);
  // The members of the sets the fixed vertices keep below 0.2 (find_quality_bounds() depends on
  // the fixed vertices alone): the end game leaves them out of its count and its walks.
  // The minimum only rises, so these are also the proofs for the end, where it stays below 0.2.
  std::vector<std::uint8_t> held(mesh.hexes.size(), 0);
  std::vector<QualityBound> proofs;
  if (!fixed.empty() && mesh_min() < kQuestionableSJ) proofs = find_quality_bounds(mesh, fixed, kQuestionableSJ);
  for (const QualityBound& b : proofs)
    for (Index h : b.hexes) held[h] = 1;
  const auto poor = [&](Index h) { return rank[h] < kQuestionableSJ; };
  const auto poor_free = [&](Index h) { return poor(h) && !held[h]; };
  const auto cluster_of = [&](Index h, auto member) {
    std::vector<Index> c{h};
    clustered[h] = 1;
    for (std::size_t i = 0; i < c.size() && c.size() < options.patch_size; ++i)
      for (Index v : mesh.hexes[c[i]])
        for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k)
          if (const Index g = inc.ids[k]; !clustered[g] && member(g)) clustered[g] = 1, c.push_back(g);
    std::sort(c.begin(), c.end());
    return c;
  };
  // More hexes below 0.2 than patch_max_poor are not stalls of the single moves but a region
  // the joint moves cannot repair (a boundary held fixed at knife edges); the walk, cheaper a
  // hex and blind to the proven ones, counts only the others.
  const auto too_many_poor = [&](auto counted) {
    std::size_t n = 0;
    for (Index h = 0; h < mesh.num_hexes(); ++h) n += counted(h);
    return n > options.patch_max_poor;
  };
  // A cluster whose joint moves all failed is not tried again while the same cluster (the same
  // hexes, the same worst one) meets the same mesh minimum and no vertex of a hex around its
  // free vertices or its worst frame's star has moved: move_patch() reads nothing else (those
  // positions, `start`, the minimum), so the tries would fail again and skipping them gives the
  // same mesh. (headsq, iso 800, h 3: the joint moves were 7.5 of 14 s; 15 of their some 45
  // failed tries were such repeats.)
  struct FailedTry {
    Index worst;
    std::vector<Index> cluster;
    double min;
    std::uint64_t at;
  };
  std::vector<FailedTry> failed;
  const auto moved_since = [&](const std::vector<Index>& hexes, std::uint64_t at) {
    for (Index g : hexes)
      for (Index v : mesh.hexes[g])
        for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k)
          for (Index w : mesh.hexes[inc.ids[k]])
            if (moved_at[w] > at) return true;
    return false;
  };
  const auto fails_again = [&](Index h, const std::vector<Index>& cluster, double min_now) {
    for (const FailedTry& f : failed) {
      if (f.worst != h || f.cluster != cluster || f.min != min_now) continue;
      return !moved_since(cluster, f.at) && !moved_since(frame_star(mesh, inc, fixed, h), f.at);
    }
    return false;
  };
  for (int round = 0; round < options.patch_rounds; ++round) {
    const auto t0 = Clock::now();
    sort_worst_first();
    if (too_many_poor(poor)) break;
    std::fill(clustered.begin(), clustered.end(), 0);
    std::size_t moved = 0;
    std::vector<FailedTry> failed_now;
    for (std::size_t i = 0; i < options.count && has(i) && rank[order[i]] < kQuestionableSJ; ++i) {
      const Index h = order[i];
      if (clustered[h]) continue;
      std::vector<Index> cluster = cluster_of(h, poor);
      const double min_before = mesh_min();
      if (options.patch_memo && fails_again(h, cluster, min_before)) {
        ++res.patch_skipped;
        failed_now.push_back({h, std::move(cluster), min_before, clock});
        continue;
      }
      // The cluster together, and where that gains nothing the worst hex of it alone, then its
      // frame's star; each with the plain model and, where that gains nothing, guarded. Each try
      // reads the minimum from before the first: a failed try moves nothing, and the cluster's
      // tries end at the first that succeeds (so no scan of every hex per try).
      const auto move = [&](const std::vector<Index>& targets, const std::vector<Index>& patch) {
        if (patch.empty() || patch.size() > options.patch_size ||
            !(opt::move_patch(mesh, inc, targets, patch, start, options, min_before) ||
              opt::move_patch(mesh, inc, targets, patch, start, options, min_before, true)))
          return false;
        for (Index v : patch) {
          unsettle_around(v);
          for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) update(inc.ids[k]);
        }
        return true;
      };
      const auto try_patch = [&](const std::vector<Index>& targets) { return move(targets, free_vertices_of(targets)); };
      // Last, h with the free vertices of every hex around the free vertices of its worst frame.
      const auto try_star = [&](Index h) { return move({h}, free_vertices_of(frame_star(mesh, inc, fixed, h))); };
      const std::uint64_t at = clock;
      if (try_patch(cluster) || (cluster.size() > 1 && try_patch({h})) || try_star(h))
        ++moved;
      else
        failed_now.push_back({h, std::move(cluster), min_before, at});
    }
    failed = std::move(failed_now);
    res.patch_moves += moved;
    res.patch_seconds += since(t0);
    res.min_sj_after = mesh_min();
    if (options.progress) options.progress({"patch", round + 1, static_cast<double>(moved), res.min_sj_after, 0});
    if (moved == 0) break;
    single_passes(std::min(options.passes, 10), options.resume_stall_passes);
  }
  // Last resort: the random walk round each cluster still below 0.2 by rank (`member`), its
  // minimum over the hexes not in `hold`.
  const auto walk = [&](auto member, const std::vector<std::uint8_t>& hold) {
    sort_worst_first();
    if (options.search_trials == 0 || too_many_poor(member)) return;
    std::fill(clustered.begin(), clustered.end(), 0);
    std::size_t gains = 0;
    for (std::size_t i = 0; has(i) && poor(order[i]); ++i) {
      const Index h = order[i];
      if (clustered[h] || !member(h)) continue;
      const auto t0 = Clock::now();
      const opt::SearchOutcome o =
          opt::search_region(mesh, inc, fixed, cluster_of(h, member), start, options, mesh_min(), hold);
      res.search_seconds += since(t0);
      ++res.searched;
      if (!(o.after > o.before)) continue;
      ++gains;
      for (Index v : o.vertices) {
        unsettle_around(v);
        for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) update(inc.ids[k]);
      }
    }
    res.search_gains += gains;
    res.min_sj_after = mesh_min();
    if (options.progress) options.progress({"search", 1, static_cast<double>(gains), res.min_sj_after, 0});
    if (gains > 0) single_passes(std::min(options.passes, 10), options.resume_stall_passes);
  };
  // Every poor hex first (a proven one still gains towards its bound: bust_in fixed, ratio
  // -0.097 -> -0.034), then, where proofs hold some, the others alone: next to a proven hex
  // they gain nothing while it counts (armadillo_in fixed, 79 -> 65 below 0.2 unproven).
  walk(poor, {});
  if (!proofs.empty()) walk(poor_free, held);
  if (res.min_sj_after < kQuestionableSJ) res.proven = std::move(proofs);
  return res;
}

}  // namespace isohex
