#include "isohex/surface/vertex_moves.hpp"

#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"
#include "isohex/volume/implicit.hpp"

#include <algorithm>
#include <cmath>

namespace isohex::surface_detail {

namespace {

// Degenerate elements (Verdict's 1e30) are as bad as flat ones, never good.
double sj_or_zero(double s) { return is_degenerate(s) ? 0.0 : s; }

double hex_sj(const HexMesh& mesh, Index h, Index v, const Vec3& y) {
  std::array<Vec3, 8> c;
  for (int i = 0; i < 8; ++i) {
    const Index w = mesh.hexes[h][i];
    c[i] = w == v ? y : mesh.points[w];
  }
  return sj_or_zero(certified_scaled_jacobian(c));
}

double quad_sj(const HexMesh& mesh, const Quad& q, Index v, const Vec3& y) {
  std::array<Vec3, 4> c;
  for (int i = 0; i < 4; ++i) c[i] = q[i] == v ? y : mesh.points[q[i]];
  return quad_scaled_jacobian(c);
}

}  // namespace

double mean_boundary_edge(const MoveContext& ctx, Index v) {
  const auto& nb = ctx.graph.boundary_neighbours;
  double sum = 0;
  for (Index k = nb.offsets[v]; k < nb.offsets[v + 1]; ++k)
    sum += (ctx.mesh.points[nb.ids[k]] - ctx.mesh.points[v]).norm();
  const Index n = nb.offsets[v + 1] - nb.offsets[v];
  return n > 0 ? sum / n : 0.0;
}

Vec3 quads_normal(const MoveContext& ctx, Index v) {
  Vec3 n = Vec3::Zero();
  const auto& vq = ctx.graph.vertex_quads;
  const auto& p = ctx.mesh.points;
  for (Index k = vq.offsets[v]; k < vq.offsets[v + 1]; ++k) {
    const Quad& q = ctx.graph.quads[vq.ids[k]];
    n += (p[q[2]] - p[q[0]]).cross(p[q[3]] - p[q[1]]);
  }
  const double nl = n.norm();
  return nl > 0 ? Vec3(n / nl) : Vec3::Zero();
}

Vec3 outward_normal(const MoveContext& ctx, Index v) {
  if (const int a = plane_axis(ctx, v); a >= 0) {
    Vec3 n = Vec3::Zero();
    n[a] = quads_normal(ctx, v)[a] < 0 ? -1.0 : 1.0;
    return n;
  }
  Vec3 g;
  ctx.field.level(ctx.mesh.points[v], g);
  const double len = g.norm();
  if (len > 0 && std::isfinite(len)) return -g / len;
  return quads_normal(ctx, v);
}

namespace {

// Within the sampled volume: the isosurface goes on past its faces (the field is extended
// there), and boundary smoothing without the hex guard carried vertices 123 mm out of cthead
// along it.
bool in_volume(const MoveContext& ctx, const Vec3& y) {
  const Volume& vol = ctx.field.volume();
  const Aabb box{vol.origin, vol.max_corner()};
  return box.contains(y, 1e-9 * (box.hi - box.lo).norm());
}

bool constrain_to_surface(const MoveContext& ctx, Index v, Vec3& y, double reach) {
  const int a = plane_axis(ctx, v);
  if (a < 0) return ctx.field.project(y, reach, ctx.level_tolerance) && y.allFinite();
  y[a] = ctx.mesh.points[v][a];
  if (!on_rim(ctx, v)) return y.allFinite();
  return ctx.field.project_in_plane(y, a, reach, ctx.level_tolerance) && y.allFinite();
}

}  // namespace

bool within_travel(const MoveContext& ctx, Index v, const Vec3& y) {
  if (!ctx.anchor || !ctx.travel) return true;
  return ((*ctx.anchor)[v] - y).squaredNorm() <= (*ctx.travel)[v] * (*ctx.travel)[v];
}

bool constrain(const MoveContext& ctx, Index v, Vec3& y, double reach) {
  return constrain_to_surface(ctx, v, y, reach) && in_volume(ctx, y);
}

Vec3 quad_umbrella(const MoveContext& ctx, Index v) {
  const auto& vq = ctx.graph.vertex_quads;
  const auto& p = ctx.mesh.points;
  Vec3 sum = Vec3::Zero();
  double area = 0;
  for (Index k = vq.offsets[v]; k < vq.offsets[v + 1]; ++k) {
    const Quad& q = ctx.graph.quads[vq.ids[k]];
    const double a = 0.5 * (p[q[2]] - p[q[0]]).cross(p[q[3]] - p[q[1]]).norm();
    sum += a * 0.25 * (p[q[0]] + p[q[1]] + p[q[2]] + p[q[3]]);
    area += a;
  }
  return area > 0 ? Vec3(sum / area - p[v]) : Vec3::Zero();
}

Vec3 boundary_step(const MoveContext& ctx, Index v, const std::vector<double>& curvature,
                   double tangential_weight, double normal_weight) {
  const Vec3 n = outward_normal(ctx, v);
  const Vec3 u = quad_umbrella(ctx, v);
  Vec3 step = tangential_weight * (u - u.dot(n) * n);
  if (normal_weight > 0) {
    const auto& nb = ctx.graph.boundary_neighbours;
    const Index count = nb.offsets[v + 1] - nb.offsets[v];
    if (count > 0) {
      double mean = 0;
      for (Index k = nb.offsets[v]; k < nb.offsets[v + 1]; ++k) mean += curvature[nb.ids[k]];
      mean /= count;
      // Δ_B H by the umbrella of H; the flow moves against it (bumps sink, dents rise).
      step -= normal_weight * (mean - curvature[v]) * n;
    }
  }
  return step;
}

Vec3 interior_step(const MoveContext& ctx, Index v, double weight) {
  const auto& vh = ctx.graph.vertex_hexes;
  Vec3 weighted = Vec3::Zero(), plain = Vec3::Zero();
  double mass = 0;
  for (Index k = vh.offsets[v]; k < vh.offsets[v + 1]; ++k) {
    const auto c = ctx.mesh.corners(vh.ids[k]);
    Vec3 centroid = Vec3::Zero();
    for (const Vec3& x : c) centroid += x;
    centroid *= 0.125;
    // Weight by the centre frame's determinant (the volume of the parallelepiped of the
    // principal axes, exact for parallelepipeds): a fraction of the exact trilinear volume's
    // cost, which dominated the sweep. An inverted hex has no mass; if all are, fall back to
    // plain centroids.
    const Vec3 a = (c[1] - c[0]) + (c[2] - c[3]) + (c[5] - c[4]) + (c[6] - c[7]);
    const Vec3 b = (c[3] - c[0]) + (c[2] - c[1]) + (c[7] - c[4]) + (c[6] - c[5]);
    const Vec3 d = (c[4] - c[0]) + (c[5] - c[1]) + (c[6] - c[2]) + (c[7] - c[3]);
    const double vol = std::max(a.dot(b.cross(d)) / 64.0, 0.0);
    weighted += vol * centroid;
    plain += centroid;
    mass += vol;
  }
  const Index count = vh.offsets[v + 1] - vh.offsets[v];
  if (count == 0) return Vec3::Zero();
  const Vec3 target = mass > 0 ? Vec3(weighted / mass) : Vec3(plain / count);
  return weight * (target - ctx.mesh.points[v]);
}

bool keeps_floors(double before, double after, double soft_floor, double hard_floor) {
  if (after >= soft_floor) return true;
  if (before >= soft_floor) return false;
  if (after >= hard_floor) return true;
  return before < hard_floor && after >= before;
}

bool move_is_acceptable(const MoveContext& ctx, Index v, const Vec3& y, bool boundary, Check check) {
  const HexMesh& mesh = ctx.mesh;
  const Vec3& x = mesh.points[v];
  const bool relax = check == Check::relax;
  const double hex_soft = relax ? ctx.hex_floor : 0.0;
  const auto& vh = ctx.graph.vertex_hexes;
  // Interior moves keep their hexes even when a pillow follows (guard_hexes off): unguarded,
  // the pull of a large hex's mass centre fed on itself and carried vertices 123 mm out of
  // cthead's volume at h 3.
  for (Index k = ctx.guard_hexes || !boundary ? vh.offsets[v] : vh.offsets[v + 1]; k < vh.offsets[v + 1]; ++k) {
    const Index h = vh.ids[k];
    const double after = hex_sj(mesh, h, v, y);
    if (after >= hex_soft) continue;  // the common case: no need for the old value
    if (!keeps_floors(hex_sj(mesh, h, v, x), after, hex_soft, 0.0)) return false;
  }
  if (!boundary) return true;
  const double quad_soft = relax ? std::max(ctx.quad_floor, ctx.quad_hard_floor) : ctx.quad_hard_floor;
  const auto& vq = ctx.graph.vertex_quads;
  for (Index k = vq.offsets[v]; k < vq.offsets[v + 1]; ++k) {
    const Quad& q = ctx.graph.quads[vq.ids[k]];
    const double after = quad_sj(mesh, q, v, y);
    if (after >= quad_soft) continue;
    if (!keeps_floors(quad_sj(mesh, q, v, x), after, quad_soft, ctx.quad_hard_floor)) return false;
  }
  return true;
}

MoveOutcome move_boundary_vertex(const MoveContext& ctx, Index v, const Vec3& step) {
  const Vec3 x = ctx.mesh.points[v];
  const bool on_surface = in_box_face(ctx, v) || std::abs(ctx.field.level(x)) <= ctx.level_tolerance;
  const double reach = ctx.projection_reach * mean_boundary_edge(ctx, v);
  const bool has_step = step.squaredNorm() > 0 && step.allFinite();
  if (!has_step && on_surface) return MoveOutcome::none;
  if (has_step) {
    double scale = 1;
    for (int k = 0; k <= ctx.max_halvings; ++k, scale *= 0.5) {
      Vec3 y = x + scale * step;
      if (constrain(ctx, v, y, reach) && within_travel(ctx, v, y) && move_is_acceptable(ctx, v, y, true, Check::relax)) {
        ctx.mesh.points[v] = y;
        return k == 0 ? MoveOutcome::accepted : MoveOutcome::halved;
      }
    }
  }
  if (!on_surface) {
    Vec3 y = x;
    if (constrain(ctx, v, y, reach) && move_is_acceptable(ctx, v, y, true, Check::project)) {
      ctx.mesh.points[v] = y;
      return has_step ? MoveOutcome::halved : MoveOutcome::accepted;
    }
  }
  return MoveOutcome::dropped;
}

MoveOutcome move_interior_vertex(const MoveContext& ctx, Index v, const Vec3& step) {
  if (!(step.squaredNorm() > 0) || !step.allFinite()) return MoveOutcome::none;
  const Vec3 x = ctx.mesh.points[v];
  double scale = 1;
  for (int k = 0; k <= ctx.max_halvings; ++k, scale *= 0.5) {
    const Vec3 y = x + scale * step;
    if (move_is_acceptable(ctx, v, y, false, Check::relax)) {
      ctx.mesh.points[v] = y;
      return k == 0 ? MoveOutcome::accepted : MoveOutcome::halved;
    }
  }
  return MoveOutcome::dropped;
}

}  // namespace isohex::surface_detail
