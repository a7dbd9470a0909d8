// Local max–min moves of boundary vertices on the isosurface: the part of surface smoothing
// that unfolds boundary quads, which a Laplacian relaxation alone leaves folded.
#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"
#include "isohex/surface/vertex_moves.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace isohex::surface_detail {

namespace {

double sj_or_zero(double s) { return is_degenerate(s) ? 0.0 : s; }

std::array<Vec3, 4> quad_corners(const HexMesh& mesh, const Quad& q, Index v, const Vec3& y) {
  std::array<Vec3, 4> c;
  for (int i = 0; i < 4; ++i) c[i] = q[i] == v ? y : mesh.points[q[i]];
  return c;
}

// The values a move of v changes, sorted ascending and compared *leximin*: the smallest
// decides, then the next, and so on. Where the smallest cannot change (three vertices on one
// point, a fan held by a pinned vertex) the next ones still may rise, and none may fall.
struct Score {
  static constexpr int kMax = 48;
  std::array<double, kMax> v{};
  int n = 0;
  double cap = 1;  // values above it count as it: good enough, free to trade
  bool lost = false;  // stopped early: a value fell below a rival's least, so it cannot beat it
  // Adds x; false (and `lost`) once x is below the least value of `rival` (sorted), whatever
  // comes after: then v sorted starts below the rival's and beats() would say no.
  bool add(double x, const Score* rival = nullptr) {
    if (n >= kMax) return true;
    const double y = std::min(x, cap);
    v[static_cast<std::size_t>(n++)] = y;
    if (rival && rival->n > 0 && y < rival->v[0] - 1e-12) lost = true;
    return !lost;
  }
  void finish() { std::sort(v.begin(), v.begin() + n); }
  [[nodiscard]] double min() const { return n > 0 ? v[0] : 1.0; }
  [[nodiscard]] bool beats(const Score& o) const {
    for (int i = 0; i < std::min(n, o.n); ++i) {
      if (v[static_cast<std::size_t>(i)] > o.v[static_cast<std::size_t>(i)] + 1e-12) return true;
      if (v[static_cast<std::size_t>(i)] < o.v[static_cast<std::size_t>(i)] - 1e-12) return false;
    }
    return false;
  }
};

}  // namespace

// The max over unit d of the min over b's quads of c·d, c the corner's cross product of
// its two edges divided by their lengths (outward; |c| = sin of the corner angle). The
// pillow hex on each quad has its edge at b pointing along −d, so a fan with no positive
// margin leaves some pillow hex inverted whatever the optimiser does. The max is taken over
// the corners' own directions, their pairwise bisectors and their sum (exact when at most two
// corners bind, close otherwise).
double fan_margin(const MoveContext& ctx, Index b, Index v, const Vec3& y) { return fan_margin(ctx.mesh, ctx.graph, b, v, y); }

double fan_margin(const HexMesh& mesh, const SurfaceGraph& graph, Index b, Index v, const Vec3& y) {
  const auto P = [&](Index w) -> const Vec3& { return w == v ? y : mesh.points[w]; };
  std::array<Vec3, 16> c;
  std::array<Vec3, 16> unit;
  int n = 0;
  const auto& vq = graph.vertex_quads;
  for (Index k = vq.offsets[b]; k < vq.offsets[b + 1] && n < 16; ++k) {
    const Quad& q = graph.quads[vq.ids[k]];
    int i = 0;
    while (i < 4 && q[i] != b) ++i;
    const Vec3 e1 = P(q[(i + 1) % 4]) - P(b), e2 = P(q[(i + 3) % 4]) - P(b);
    const double l = e1.norm() * e2.norm();
    if (!(l > 0)) return 0.0;  // a collapsed edge: no direction helps
    c[n] = e1.cross(e2) / l;
    const double cl = c[n].norm();
    unit[n] = cl > 0 ? Vec3(c[n] / cl) : Vec3::Zero();
    ++n;
  }
  if (n == 0) return 1.0;
  const auto margin = [&](const Vec3& d) {
    const double l = d.norm();
    if (!(l > 0)) return -1.0;
    double m = 1.0;
    for (int i = 0; i < n; ++i) m = std::min(m, c[i].dot(d) / l);
    return m;
  };
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < n; ++i) sum += unit[i];
  double best = margin(sum);
  for (int i = 0; i < n; ++i) {
    best = std::max(best, margin(unit[i]));
    for (int j = i + 1; j < n; ++j) best = std::max(best, margin(unit[i] + unit[j]));
  }
  return best;
}

namespace {

// With a rival, stops (Score::lost) at the first value below the rival's least: most trial
// points of the max–min search lose on their first quad or fan, and the rest of their fans
// were a third of the surface smoothing's time on cthead h 2.
Score score_around(const MoveContext& ctx, Index v, const Vec3& y, const std::vector<Vec3>& turned, double cap,
                   const Score* rival = nullptr) {
  const auto& vq = ctx.graph.vertex_quads;
  Score s;
  s.cap = cap;
  for (Index k = vq.offsets[v]; k < vq.offsets[v + 1]; ++k) {
    const Quad& q = ctx.graph.quads[vq.ids[k]];
    // A quad may not turn over from where it is now (a fold-over of a whole quad, which
    // Verdict's value cannot see); one that has turned over counts as such until it faces
    // its outward reference again.
    const Vec3& ref = turned[static_cast<std::size_t>(vq.ids[k])];
    const Vec3 now = ref.squaredNorm() > 0 ? ref
                                          : Vec3((ctx.mesh.points[q[2]] - ctx.mesh.points[q[0]])
                                                     .cross(ctx.mesh.points[q[3]] - ctx.mesh.points[q[1]]));
    if (!s.add(oriented_quad_sj(quad_corners(ctx.mesh, q, v, y), now), rival)) return s;
  }
  // The fans whose corners move with v: its own and its edge neighbours'.
  if (!s.add(fan_margin(ctx, v, v, y), rival)) return s;
  const auto& nb = ctx.graph.boundary_neighbours;
  for (Index k = nb.offsets[v]; k < nb.offsets[v + 1]; ++k)
    if (!s.add(fan_margin(ctx, nb.ids[k], v, y), rival)) return s;
  s.finish();
  return s;
}

// With guard_hexes: no hex around v may cross the soft floor or 0 downward, nor get worse below 0.
bool hexes_allow(const MoveContext& ctx, Index v, const Vec3& y) {
  if (!ctx.guard_hexes) return true;
  const auto& vh = ctx.graph.vertex_hexes;
  for (Index k = vh.offsets[v]; k < vh.offsets[v + 1]; ++k) {
    const Index h = vh.ids[k];
    std::array<Vec3, 8> c = ctx.mesh.corners(h);
    for (int i = 0; i < 8; ++i)
      if (ctx.mesh.hexes[h][i] == v) c[i] = y;
    const double after = sj_or_zero(certified_scaled_jacobian(c));
    if (after >= ctx.hex_floor) continue;
    if (!keeps_floors(sj_or_zero(certified_scaled_jacobian(ctx.mesh.corners(h))), after, ctx.hex_floor, 0.0)) return false;
  }
  return true;
}

}  // namespace

double oriented_quad_sj(const std::array<Vec3, 4>& c, const Vec3& reference) {
  // Verdict's centre normal is the diagonals' cross product (up to a factor 2).
  const Vec3 centre_normal = (c[2] - c[0]).cross(c[3] - c[1]);
  if (reference.squaredNorm() > 0 && !(centre_normal.dot(reference) > 0)) return kFlippedQuad;
  return quad_scaled_jacobian(c);
}

MoveOutcome raise_worst_quad(const MoveContext& ctx, Index v, double radius, int levels,
                             const std::vector<Vec3>& turned, double cap) {
  const Vec3 x = ctx.mesh.points[v];
  const Score current = score_around(ctx, v, x, turned, cap);
  // The tangent plane of the isosurface at v.
  const Vec3 n = outward_normal(ctx, v);
  const Vec3 a = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  const Vec3 b = n.cross(a);
  const auto& nb = ctx.graph.boundary_neighbours;
  if (nb.offsets[v + 1] == nb.offsets[v]) return MoveOutcome::none;
  const double edge = mean_boundary_edge(ctx, v);

  Vec3 best = x;
  Score best_score = current;
  double step = radius * edge;
  constexpr int kDirections = 8;
  for (int level = 0; level < levels; ++level, step *= 0.5) {
    for (int d = 0; d < kDirections; ++d) {
      const double t = 2 * std::numbers::pi * d / kDirections;
      Vec3 y = x + step * (std::cos(t) * a + std::sin(t) * b);
      if (!constrain(ctx, v, y, 2 * edge) || !within_travel(ctx, v, y)) continue;
      const Score value = score_around(ctx, v, y, turned, cap, &best_score);
      if (!value.lost && value.beats(best_score) && hexes_allow(ctx, v, y)) {
        best_score = value;
        best = y;
      }
    }
    if (best != x) break;  // the coarsest step that helps: keeps the search short
  }
  if (best == x) return MoveOutcome::dropped;
  ctx.mesh.points[v] = best;
  return MoveOutcome::accepted;
}

void update_normals(const MoveContext& ctx, const std::vector<std::uint8_t>& on_isosurface,
                    std::vector<std::uint8_t>& stale, std::vector<Vec3>& normal) {
  const auto& g = ctx.graph;
  normal.resize(ctx.mesh.points.size(), Vec3::Zero());
  // Every entry is written by one task: the same bits for any thread count.
  tbb::parallel_for(std::size_t{0}, normal.size(), [&](std::size_t v) {
    if (!stale[v]) return;
    stale[v] = 0;
    if (g.on_boundary[v] && on_isosurface[v]) normal[v] = outward_normal(ctx, static_cast<Index>(v));
  });
}

void turned_over_quads(const MoveContext& ctx, const std::vector<Vec3>& normal, std::vector<Vec3>& turned) {
  const auto& g = ctx.graph;
  const auto& p = ctx.mesh.points;
  turned.assign(g.quads.size(), Vec3::Zero());
  tbb::parallel_for(std::size_t{0}, g.quads.size(), [&](std::size_t i) {
    const Quad& q = g.quads[i];
    const Vec3 n = (p[q[2]] - p[q[0]]).cross(p[q[3]] - p[q[1]]);
    const Vec3 field = normal[q[0]] + normal[q[1]] + normal[q[2]] + normal[q[3]];
    if (!(n.dot(field) < 0)) return;
    const Hex& h = ctx.mesh.hexes[g.quad_hex[i]];
    const auto& opposite = kHexFaces[static_cast<std::size_t>(g.quad_face[i] ^ 1)];  // faces pair up 0-1, 2-3, 4-5
    Vec3 across = 0.25 * (p[q[0]] + p[q[1]] + p[q[2]] + p[q[3]]);
    for (int c : opposite) across -= 0.25 * p[h[c]];
    if (!(n.dot(across) < 0)) return;
    const double fl = field.norm(), al = across.norm();
    if (fl > 0 && al > 0) turned[i] = field / fl + across / al;
  });
}

}  // namespace isohex::surface_detail
