// The worst pass's move of one vertex: a max–min step on the scaled-Jacobian frames and the
// ratio terms around it (improve_worst() in worst.cpp runs it over the worst hexes).
#include "isohex/optimize/worst_move.hpp"

#include "isohex/optimize/feasibility.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"
#include "isohex/quality/summary.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace isohex::opt {

namespace {

// The lowest scaled Jacobian of the hexes around v with v placed at x. With `valid`, also
// whether every hex that is valid now (scaled Jacobian > 0) stays valid there and no edge at
// v is shorter than `shrink` times its length in `start` (the mesh when the pass began): the
// scaled Jacobian is blind to edge lengths, so a max–min ascent alone may shrink an edge
// towards zero (on a sphere's mesh it drove the mean inverse mean ratio from 1.3 to 81).
// With `ratio`, also the smallest jacobian_ratio_bound() of those hexes: the scaled Jacobian
// samples det J at nine points, so the pass must not buy them with a distorted interior.
// With `edges`, also the largest edge ratio of those hexes.
// With `limits` (and all of the above), a trial point's: it stops at the first hex past which
// the point must fail (invalid, more hexes below 0.2, or the minimum, ratio or edge ratio
// beyond its limit; each only worsens with more hexes, so the answer is the same), returning
// -inf. Most trial points fail (cthead h 4: 70 % of them), and the hexes after the one that
// fails them were half of the worst pass's certificates.
struct TrialLimits {
  int questionable;
  double min, ratio, edges;
};
double local_min(const HexMesh& mesh, const Incidence& inc, Index v, const Vec3& x, bool* valid = nullptr,
                 int* questionable = nullptr, const std::vector<Vec3>* start = nullptr, double shrink = 0,
                 double* ratio = nullptr, double* edges = nullptr, const TrialLimits* limits = nullptr) {
  constexpr double kFails = -std::numeric_limits<double>::infinity();
  double lo = 2.0;
  if (valid) *valid = true;
  if (questionable) *questionable = 0;
  if (ratio) *ratio = 1.0;
  if (edges) *edges = 1.0;
  for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) {
    const Index h = inc.ids[i];
    const auto p = corners_with(mesh, h, v, x);
    double q;
    if (ratio) {  // both from one evaluation of the hex's Bernstein coefficients
      const CertifiedQuality c = certified_quality(p);
      q = is_degenerate(c.scaled_jacobian) ? -2.0 : c.scaled_jacobian;
      *ratio = std::min(*ratio, c.ratio_bound);
    } else {
      q = worst_sj_value(p);
    }
    lo = std::min(lo, q);
    if (questionable) *questionable += q < kQuestionableSJ;
    if (limits && (lo < limits->min || *ratio < limits->ratio || *questionable > limits->questionable)) return kFails;
    if (edges) *edges = std::max(*edges, edge_ratio(p));  // Verdict's, as `isohex quality` reports it
    if (limits && *edges > limits->edges) return kFails;
    if (!valid) continue;
    if (q <= 0 && worst_sj_value(mesh.corners(h)) > 0) *valid = false;
    for (const auto& e : kHexEdges) {
      const Index a = mesh.hexes[h][e[0]], b = mesh.hexes[h][e[1]];
      if (start && (a == v || b == v) &&
          (p[e[0]] - p[e[1]]).squaredNorm() < shrink * shrink * ((*start)[a] - (*start)[b]).squaredNorm())
        *valid = false;
    }
    if (limits && !*valid) return kFails;
  }
  return lo;
}

// The largest Bernstein coefficient of det J of each hex around v as the mesh stands (in
// incidence order; 0 for a hex with none positive): the ratio terms' constant normalisation
// during one move of v.
std::vector<double> ratio_norms(const HexMesh& mesh, const Incidence& inc, Index v) {
  std::vector<double> m;
  for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) m.push_back(bernstein_norm(mesh.corners(inc.ids[i])));
  return m;
}

// The Bernstein coefficients of det J of each hex around v over its norm, as affine functions
// of v's place (ratio_coefficients). Their minimum bounds the hex's jacobian ratio from
// below, so a max–min move on them raises the element's interior, not only Verdict's nine
// samples.
void ratio_terms(const HexMesh& mesh, const Incidence& inc, Index v, const Vec3& x, bool value_only,
                 const std::vector<double>& norms, std::vector<Affine>& out) {
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
    ratio_coefficients(p, kRatioWeight, m, corner, b, value_only ? nullptr : &g);
    for (int n = 0; n < 27; ++n) out.push_back({value_only ? Vec3::Zero() : g[k][n], b[n]});
  }
}

// The scaled Jacobians of the frames (of the hexes around v) that v's position changes, each
// as its value and gradient in that position (scaled_frame). Verdict's hex value is the
// minimum of these and of the frames v is not in. With `value_only`, the gradients are left
// zero; with `norms` (ratio_norms()), ratio_terms() come too.
void frame_values(const HexMesh& mesh, const Incidence& inc, Index v, const Vec3& x, bool value_only,
                  const std::vector<double>* norms, std::vector<Affine>& out) {
  out.clear();
  if (norms) ratio_terms(mesh, inc, v, x, value_only, *norms, out);
  for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) {
    const Index h = inc.ids[i];
    auto p = mesh.corners(h);
    int k = 0;
    while (mesh.hexes[h][k] != v) ++k;
    p[k] = x;
    for (int t = 0; t < kFrames; ++t) {
      const Vec3& c = frame_coefficient(t, k);
      if (!c.isZero()) out.push_back(scaled_frame(frame(p, t, 1.0), c, value_only));
    }
  }
}

double lowest(const std::vector<Affine>& f) {
  double lo = 2.0;
  for (const Affine& a : f) lo = std::min(lo, a.b);
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
}  // namespace

bool worst_move(HexMesh& mesh, const Incidence& inc, Index v, const std::vector<Vec3>& start,
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
  const double len = mean_edge_at(mesh, inc, v);
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
    std::vector<Affine> f;
    std::vector<double> w;
    double now;          // the smallest term to raise
    std::size_t raised;  // the terms to raise come first; the constraints follow them
  };
  // The model at x and a trial's, in per-thread buffers (a move runs to its end on its thread;
  // their allocations were a twentieth of the pass's instructions).
  thread_local Model m, my;
  thread_local std::vector<Affine> held;
  const auto terms = [&](const Vec3& y, bool value_only, Model& out) {
    frame_values(mesh, inc, v, y, value_only, std::isnan(held_ratio) ? ratio : nullptr, out.f);
    out.now = lowest(out.f);
    out.raised = out.f.size();
    out.w.assign(out.f.size(), 1.0);
    if (!std::isnan(held_ratio)) {
      held.clear();
      ratio_terms(mesh, inc, v, y, value_only, norms, held);
      for (Affine& a : held) a.b -= held_ratio, out.f.push_back(a), out.w.push_back(1e-6);
    }
  };
  for (int phase = 1; phase <= (options.ratio_terms ? 2 : 1); ++phase) {
    if (phase == 2) {
      std::vector<Affine> r;
      ratio_terms(mesh, inc, v, x, true, norms, r);
      if (r.empty()) break;
      held_ratio = lowest(r);
    }
    double box = options.step * len;
    for (int model = 0; model < options.models; ++model) {
      terms(x, false, m);
      std::vector<Affine>& f = m.f;
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
        for (Affine& a : f) a.a = Vec3(a.a.dot(t1), a.a.dot(t2), 0.0);
      }
      f.push_back({Vec3::Zero(), options.target});
      w.push_back(1.0);
      bool gained = false;
      for (int trial = 0; trial < options.trials && !gained; ++trial, box *= 0.5) {
        const MaxMin r = max_min_affine(f, w, box);
        if (!r.ok || !(r.s > now + 1e-9)) break;  // no ascent even in the model: a max–min point
        Vec3 y = slides ? Vec3(x + r.d[0] * t1 + r.d[1] * t2) : Vec3(x + r.d);
        if (surface && !surface->put_back(v, y, n, len)) continue;  // off the surface (or band): refused
        bool valid = false;
        int below = 0;
        double ratio_y = 1, edges_y = 1;
        // A negative local minimum may rise while a valid neighbour is inverted on the way;
        // raising one hex by bending several others below 0.2 is no gain.
        const TrialLimits limits{below0, sj_floor, ratio_floor, edge_cap};
        const double q =
            local_min(mesh, inc, v, y, &valid, &below, &start, options.min_edge_shrink, &ratio_y, &edges_y, &limits);
        if (!valid || below > below0 || q < sj_floor || ratio_y < ratio_floor || edges_y > edge_cap) continue;
        terms(y, true, my);
        if (!(my.now > now + 1e-9)) continue;
        // Phase 2: the ratio terms held, and the certified ratio around v too; the scaled
        // Jacobian it raises may not fall.
        if (phase == 2 && (ratio_y < ratio0 || q < m0 || std::any_of(my.f.begin() + static_cast<std::ptrdiff_t>(my.raised), my.f.end(),
                                                           [](const Affine& a) { return a.b < 0; })))
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

}  // namespace isohex::opt
