// Local max–min moves of boundary vertices on the isosurface: the part of surface smoothing
// that unfolds boundary quads, which a Laplacian relaxation alone leaves folded.
#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/surface/vertex_moves.hpp"

#include <algorithm>
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

// The smallest and the sum of the oriented_quad_sj() of the boundary quads around v, with v
// at y. Compared lexicographically: the sum breaks ties of the minimum, e.g. where three
// vertices sit on one point and moving one of them leaves the minimum at 0.
struct Score {
  double min = 1, sum = 0;
  [[nodiscard]] bool beats(const Score& o) const {
    return min > o.min + 1e-12 || (min >= o.min && sum > o.sum + 1e-9);
  }
};

Score score_around(const MoveContext& ctx, Index v, const Vec3& y, const std::vector<Vec3>& turned) {
  const auto& vq = ctx.graph.vertex_quads;
  Score s;
  for (Index k = vq.offsets[v]; k < vq.offsets[v + 1]; ++k) {
    const Quad& q = ctx.graph.quads[vq.ids[k]];
    // A quad may not turn over from where it is now (a fold-over of a whole quad, which
    // Verdict's value cannot see); one that has turned over counts as such until it faces
    // its outward reference again.
    const Vec3& ref = turned[static_cast<std::size_t>(vq.ids[k])];
    const Vec3 now = ref.squaredNorm() > 0 ? ref
                                          : Vec3((ctx.mesh.points[q[2]] - ctx.mesh.points[q[0]])
                                                     .cross(ctx.mesh.points[q[3]] - ctx.mesh.points[q[1]]));
    const double sj = oriented_quad_sj(quad_corners(ctx.mesh, q, v, y), now);
    s.min = std::min(s.min, sj);
    s.sum += sj;
  }
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
    const double after = sj_or_zero(scaled_jacobian(c));
    if (after >= ctx.hex_floor) continue;
    if (!keeps_floors(sj_or_zero(scaled_jacobian(ctx.mesh.corners(h))), after, ctx.hex_floor, 0.0)) return false;
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
                             const std::vector<Vec3>& turned) {
  const Vec3 x = ctx.mesh.points[v];
  const Score current = score_around(ctx, v, x, turned);
  // The tangent plane of the isosurface at v.
  const Vec3 n = outward_normal(ctx, v);
  const Vec3 a = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  const Vec3 b = n.cross(a);
  const auto& nb = ctx.graph.boundary_neighbours;
  double edge = 0;
  for (Index k = nb.offsets[v]; k < nb.offsets[v + 1]; ++k) edge += (ctx.mesh.points[nb.ids[k]] - x).norm();
  const Index count = nb.offsets[v + 1] - nb.offsets[v];
  if (count == 0) return MoveOutcome::none;
  edge /= count;

  Vec3 best = x;
  Score best_score = current;
  double step = radius * edge;
  constexpr int kDirections = 8;
  for (int level = 0; level < levels; ++level, step *= 0.5) {
    for (int d = 0; d < kDirections; ++d) {
      const double t = 2 * std::numbers::pi * d / kDirections;
      Vec3 y = x + step * (std::cos(t) * a + std::sin(t) * b);
      if (!constrain(ctx, v, y, 2 * edge)) continue;
      const Score value = score_around(ctx, v, y, turned);
      if (value.beats(best_score) && hexes_allow(ctx, v, y)) {
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

std::vector<Vec3> turned_over_quads(const MoveContext& ctx, const std::vector<std::uint8_t>& on_isosurface) {
  const auto& g = ctx.graph;
  const auto& p = ctx.mesh.points;
  std::vector<Vec3> turned(g.quads.size(), Vec3::Zero());
  for (std::size_t i = 0; i < g.quads.size(); ++i) {
    const Quad& q = g.quads[i];
    const Vec3 n = (p[q[2]] - p[q[0]]).cross(p[q[3]] - p[q[1]]);
    Vec3 field = Vec3::Zero();
    for (Index v : q)
      if (on_isosurface[v]) field += outward_normal(ctx, v);
    if (!(n.dot(field) < 0)) continue;
    const Hex& h = ctx.mesh.hexes[g.quad_hex[i]];
    const auto& opposite = kHexFaces[static_cast<std::size_t>(g.quad_face[i] ^ 1)];  // faces pair up 0-1, 2-3, 4-5
    Vec3 across = 0.25 * (p[q[0]] + p[q[1]] + p[q[2]] + p[q[3]]);
    for (int c : opposite) across -= 0.25 * p[h[c]];
    if (!(n.dot(across) < 0)) continue;
    const double fl = field.norm(), al = across.norm();
    if (fl > 0 && al > 0) turned[i] = field / fl + across / al;
  }
  return turned;
}

}  // namespace isohex::surface_detail
