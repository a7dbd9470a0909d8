#include "isohex/surface/smooth_surface.hpp"

#include "isohex/error.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/summary.hpp"
#include "isohex/surface/surface_graph.hpp"
#include "isohex/surface/vertex_moves.hpp"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace isohex {

using surface_detail::MoveContext;
using surface_detail::MoveOutcome;

namespace {

constexpr double kSurfaceGuarantee = 1e-6;  // |L| ≤ this × range at the end (documented)

void check_range(const char* name, double value, double lo, double hi) {
  if (!(value >= lo && value <= hi))
    throw Error(fmt::format("surface smoothing: option {} = {} is outside [{}, {}]", name, value, lo, hi));
}

void check_inputs(const HexMesh& mesh, const IsoField& field, const SurfaceSmoothingOptions& o) {
  if (mesh.hexes.empty()) throw Error("surface smoothing: the mesh has no hexes");
  const Index nv = mesh.num_vertices();
  for (Index h = 0; h < mesh.num_hexes(); ++h)
    for (int c = 0; c < 8; ++c)
      if (mesh.hexes[h][c] < 0 || mesh.hexes[h][c] >= nv)
        throw Error(fmt::format("surface smoothing: hex {}: vertex id {} at corner {} is out of range [0, {})", h,
                                mesh.hexes[h][c], c, nv));
  for (Index v = 0; v < nv; ++v)
    if (!mesh.points[v].allFinite())
      throw Error(fmt::format("surface smoothing: vertex {} has a non-finite coordinate", v));
  if (mesh.has_fixed() && mesh.fixed.size() != mesh.points.size())
    throw Error(fmt::format("surface smoothing: mesh.fixed has {} entries for {} vertices", mesh.fixed.size(), nv));
  if (!o.pinned.empty() && o.pinned.size() != mesh.points.size())
    throw Error(fmt::format("surface smoothing: the pinned mask has {} entries for {} vertices", o.pinned.size(), nv));
  if (!o.planar.empty() && o.planar.size() != mesh.points.size())
    throw Error(fmt::format("surface smoothing: the planar mask has {} entries for {} vertices", o.planar.size(), nv));
  for (std::size_t v = 0; v < o.planar.size(); ++v)
    if (o.planar[v] < -1 || o.planar[v] > 2)
      throw Error(fmt::format("surface smoothing: planar[{}] = {} is not an axis (0-2) or -1", v, o.planar[v]));

  const Volume& vol = field.volume();
  if (vol.dims[0] < 2 || vol.dims[1] < 2 || vol.dims[2] < 2)
    throw Error(fmt::format("surface smoothing: the field's grid is {} x {} x {}; it needs at least 2 points per axis",
                            vol.dims[0], vol.dims[1], vol.dims[2]));
  if (vol.values.size() != vol.size())
    throw Error(fmt::format("surface smoothing: the field has {} values for a {} x {} x {} grid ({} expected)",
                            vol.values.size(), vol.dims[0], vol.dims[1], vol.dims[2], vol.size()));
  if (!(field.value_range() > 0) || !std::isfinite(field.value_range()))
    throw Error("surface smoothing: the field's values are all equal (or not finite): there is no isosurface");

  check_range("iterations", o.iterations, 0, 1e6);
  check_range("tangential_weight", o.tangential_weight, 0, 1);
  check_range("normal_weight", o.normal_weight, 0, 0.5);
  check_range("interior_weight", o.interior_weight, 0, 1);
  check_range("interior_layers", o.interior_layers, 0, 1000);
  check_range("interior_sweeps", o.interior_sweeps, 0, 1000);
  check_range("min_hex_sj", o.min_hex_sj, 0, 1);
  check_range("min_quad_sj", o.min_quad_sj, 0, 1);
  check_range("max_halvings", o.max_halvings, 0, 60);
  check_range("crease_angle_degrees", o.crease_angle_degrees, 1e-9, 180);
  check_range("field_crease_angle_degrees", o.field_crease_angle_degrees, 0, 180);
  check_range("level_tolerance", o.level_tolerance, 1e-15, kSurfaceGuarantee);
  check_range("projection_reach", o.projection_reach, 1e-6, 100);
  check_range("convergence", o.convergence, 0, 1);
  check_range("max_travel", o.max_travel, 1e-6, 100);
  check_range("worst_passes", o.worst_passes, 0, 1e6);
  check_range("stall_iterations", o.stall_iterations, 0, 1e6);
  check_range("stall_gain", o.stall_gain, 0, 1);
  check_range("worst_target", o.worst_target, 0, 1);
  check_range("worst_radius", o.worst_radius, 1e-9, 2);
  check_range("worst_levels", o.worst_levels, 1, 30);
}

// A boundary vertex more than a cell outside the grid sees a clamped field, constant along
// the grid's axis there (a scan cut at the neck continues as a cylinder): it cannot slide
// along the surface, so it is pinned. Returns how many were.
std::size_t pin_outside_grid(const HexMesh& mesh, const std::vector<std::uint8_t>& on_boundary,
                             std::vector<std::uint8_t>& pinned, const Volume& vol) {
  const Vec3 lo = vol.origin - vol.spacing, hi = vol.max_corner() + vol.spacing;
  std::size_t n = 0;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    if (!on_boundary[v] || pinned[v]) continue;
    const Vec3& p = mesh.points[v];
    if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) {
      pinned[v] = 1;
      ++n;
    }
  }
  return n;
}

SurfaceQuality quality_of(const HexMesh& mesh, const surface_detail::SurfaceGraph& graph) {
  SurfaceQuality q;
  const QuadSummary qs = summarize_quads(mesh, graph.quads);
  q.fan_margin_min = 1;
  for (Index b = 0; b < mesh.num_vertices(); ++b) {
    if (!graph.on_boundary[b]) continue;
    const double m = surface_detail::fan_margin(mesh, graph, b, b, mesh.points[b]);
    q.fan_margin_min = std::min(q.fan_margin_min, m);
    q.fans_below += m < kQuestionableSJ;
  }
  q.num_quads = qs.count;
  q.quad_sj_min = qs.min;
  q.quad_sj_mean = qs.mean;
  q.quads_below = qs.below;
  const MetricSummary hs = summarize(HexMetric::scaled_jacobian, scaled_jacobians(mesh), 0);
  q.hex_sj_min = hs.min;
  q.hexes_inverted = hs.inverted;
  q.hexes_degenerate = hs.degenerate;
  return q;
}

// Runs `move` on every vertex of every class, classes in order, members in parallel, and
// tallies the outcomes in member order.
template <class Move>
void sweep(const std::vector<std::vector<Index>>& classes, std::vector<MoveOutcome>& outcome,
           SurfaceSmoothingReport& report, Move&& move) {
  for (const auto& cls : classes) {
    tbb::parallel_for(std::size_t{0}, cls.size(), [&](std::size_t i) { outcome[cls[i]] = move(cls[i]); });
    for (Index v : cls) {
      if (outcome[v] == MoveOutcome::halved) ++report.moves_halved;
      if (outcome[v] == MoveOutcome::dropped) ++report.moves_dropped;
    }
  }
}

double quad_sj_of(const HexMesh& mesh, const Quad& q) {
  return quad_scaled_jacobian({mesh.points[q[0]], mesh.points[q[1]], mesh.points[q[2]], mesh.points[q[3]]});
}

// Passes of max–min moves over the free boundary vertices of quads below the target (or
// turned over), in classes none of whose members reads another's position (the score of v
// reads the fans of its neighbours), until a pass moves nothing.
void worst_quad_passes(const MoveContext& ctx, const std::vector<Index>& sliding,
                       const std::vector<std::uint8_t>& on_isosurface, const SurfaceSmoothingOptions& options,
                       SurfaceSmoothingReport& report) {
  const HexMesh& mesh = ctx.mesh;
  std::vector<std::uint8_t> can_move(mesh.points.size(), 0);
  for (Index v : sliding) can_move[v] = 1;
  std::vector<MoveOutcome> outcome(mesh.points.size(), MoveOutcome::none);
  std::vector<std::uint8_t> stale(mesh.points.size(), 1), active;
  std::vector<Vec3> normal, turned;
  std::vector<Index> work;
  // A vertex whose search found nothing finds nothing again until a vertex it reads moves:
  // raise_worst_quad() reads the quads of v and of its boundary neighbours, the turned flags
  // of v's quads as the pass began (the normals of their vertices: their quads' vertices for a
  // box-face vertex; their hexes' opposite faces) and with the hex guard the corners of v's
  // hexes; all within two quad rings of v or in its hexes. So a vertex is searched again once
  // such a vertex has moved in or after the pass where its search found nothing (a move
  // earlier in that pass shows in the next pass's turned flags), and a settled vertex is left
  // as its search would leave it, in the same classes (the same mesh: on cthead h 2 over half
  // of the last passes' searches were repeats).
  std::vector<int> dropped_in(mesh.points.size(), -1), touched_in(mesh.points.size(), -1);
  const auto touch_around = [&](Index w, int pass) {
    const auto& vq = ctx.graph.vertex_quads;
    for (Index k = vq.offsets[w]; k < vq.offsets[w + 1]; ++k)
      for (Index x : ctx.graph.quads[vq.ids[k]])
        for (Index j = vq.offsets[x]; j < vq.offsets[x + 1]; ++j)
          for (Index y : ctx.graph.quads[vq.ids[j]]) touched_in[y] = pass;
    for (Index k = ctx.graph.vertex_hexes.offsets[w]; k < ctx.graph.vertex_hexes.offsets[w + 1]; ++k)
      for (Index y : mesh.hexes[ctx.graph.vertex_hexes.ids[k]]) touched_in[y] = pass;
  };
  const auto settled = [&](Index v) { return dropped_in[v] >= 0 && touched_in[v] < dropped_in[v]; };
  for (int pass = 0; pass < options.worst_passes; ++pass) {
    surface_detail::update_normals(ctx, on_isosurface, stale, normal);
    surface_detail::turned_over_quads(ctx, normal, turned);
    active.assign(mesh.points.size(), 0);
    for (std::size_t i = 0; i < ctx.graph.quads.size(); ++i) {
      const Quad& q = ctx.graph.quads[i];
      if (turned[i].squaredNorm() > 0 || quad_sj_of(mesh, q) < options.worst_target)
        for (Index v : q) active[v] = can_move[v];
    }
    work.clear();
    for (Index v : sliding)
      if (active[v]) work.push_back(v);
    if (work.empty()) break;
    report.worst_passes = pass + 1;
    std::size_t moved = 0;
    for (const auto& cls : surface_detail::read_disjoint_classes(work, ctx.graph, ctx.guard_hexes ? &mesh : nullptr)) {
      tbb::parallel_for(std::size_t{0}, cls.size(), [&](std::size_t i) {
        outcome[cls[i]] = settled(cls[i]) ? MoveOutcome::dropped
                                          : surface_detail::raise_worst_quad(ctx, cls[i], options.worst_radius,
                                                                             options.worst_levels, turned,
                                                                             options.worst_target);
      });
      for (Index v : cls) {
        if (outcome[v] != MoveOutcome::accepted) {
          if (!settled(v)) dropped_in[v] = pass;
          continue;
        }
        dropped_in[v] = -1;
        ++moved;
        for (Index k = ctx.graph.vertex_quads.offsets[v]; k < ctx.graph.vertex_quads.offsets[v + 1]; ++k)
          for (Index x : ctx.graph.quads[ctx.graph.vertex_quads.ids[k]]) stale[x] = 1;
        touch_around(v, pass);
      }
    }
    report.worst_moves += moved;
    if (moved == 0) break;
  }
}

}  // namespace

SurfaceQuality surface_quality(const HexMesh& mesh) {
  return quality_of(mesh, surface_detail::build_surface_graph(mesh, 0.5));
}

namespace {

// Per boundary vertex, a bit per box face it lies on (bit 2a: low side of axis a, 2a+1: high).
std::vector<std::uint8_t> box_faces(const HexMesh& mesh, const Vec3& lo, const Vec3& hi, double relative_tolerance) {
  const double tol = relative_tolerance * (hi - lo).norm();
  std::vector<std::uint8_t> faces(mesh.points.size(), 0);
  const std::vector<std::uint8_t> boundary = boundary_vertex_mask(mesh);
  for (std::size_t v = 0; v < mesh.points.size(); ++v) {
    if (!boundary[v]) continue;
    const Vec3& p = mesh.points[v];
    for (int a = 0; a < 3; ++a) {
      if (std::abs(p[a] - lo[a]) <= tol) faces[v] |= static_cast<std::uint8_t>(1u << (2 * a));
      if (std::abs(p[a] - hi[a]) <= tol) faces[v] |= static_cast<std::uint8_t>(1u << (2 * a + 1));
    }
  }
  return faces;
}

}  // namespace

std::vector<std::uint8_t> volume_box_vertices(const HexMesh& mesh, const Volume& volume, double relative_tolerance) {
  std::vector<std::uint8_t> mask = box_faces(mesh, volume.origin, volume.max_corner(), relative_tolerance);
  for (std::uint8_t& m : mask) m = m != 0;
  return mask;
}

std::vector<std::int8_t> box_face_axes(const HexMesh& mesh, const Vec3& lo, const Vec3& hi, double relative_tolerance) {
  const std::vector<std::uint8_t> faces = box_faces(mesh, lo, hi, relative_tolerance);
  std::vector<std::int8_t> axis(faces.size(), -1);
  for (std::size_t v = 0; v < faces.size(); ++v)
    for (int a = 0; a < 3; ++a)
      if (faces[v] == (1u << (2 * a)) || faces[v] == (1u << (2 * a + 1))) axis[v] = static_cast<std::int8_t>(a);
  return axis;
}

// Internal plane codes (MoveContext::planar): the axis for a vertex whose quads all lie in its
// plane, the axis + 3 for one on the rim where the plane meets the isosurface.
std::vector<std::int8_t> plane_codes(const HexMesh& mesh, const surface_detail::SurfaceGraph& graph,
                                     const std::vector<std::int8_t>& planar) {
  std::vector<std::int8_t> code(planar);
  for (std::size_t v = 0; v < code.size(); ++v) {
    const int a = code[v];
    if (a < 0) continue;
    const auto& vq = graph.vertex_quads;
    for (Index k = vq.offsets[v]; k < vq.offsets[v + 1]; ++k)
      for (Index w : graph.quads[vq.ids[k]])
        if (mesh.points[w][a] != mesh.points[v][a]) code[v] = static_cast<std::int8_t>(a + 3);
  }
  return code;
}

SurfaceSmoothingReport smooth_surface(HexMesh& mesh, const IsoField& field, const SurfaceSmoothingOptions& options) {
  check_inputs(mesh, field, options);
  const Index nv = mesh.num_vertices();
  std::vector<std::uint8_t> pinned(static_cast<std::size_t>(nv), 0);
  for (Index v = 0; v < nv; ++v)
    pinned[v] = (options.use_mesh_fixed && mesh.has_fixed() && mesh.fixed[v]) || (!options.pinned.empty() && options.pinned[v]);

  const double crease_cos = std::cos(options.crease_angle_degrees * std::numbers::pi / 180.0);
  // A feature must show in the field too: where DC quads fold over a smooth (if noisy)
  // isosurface their normals jump but the field's do not, and the max-min pass must move them.
  const double field_crease_cos = std::cos(options.field_crease_angle_degrees * std::numbers::pi / 180.0);
  const auto field_normal = [&](Index v) {
    Vec3 g;
    field.level(mesh.points[v], g);
    const double len = g.norm();
    return len > 0 && std::isfinite(len) ? Vec3(-g / len) : Vec3::Zero();
  };
  const surface_detail::SurfaceGraph graph =
      surface_detail::build_surface_graph(mesh, crease_cos, field_normal, field_crease_cos);
  const std::size_t outside_grid = pin_outside_grid(mesh, graph.on_boundary, pinned, field.volume());

  SurfaceSmoothingReport report;
  report.outside_grid = outside_grid;
  report.before = quality_of(mesh, graph);

  // Free boundary vertices: sliding ones and crease ones (projection only).
  std::vector<Index> boundary;
  for (Index v = 0; v < nv; ++v) {
    if (pinned[v]) ++report.pinned_vertices;
    if (!graph.on_boundary[v] || pinned[v]) continue;
    boundary.push_back(v);
    if (graph.on_crease[v]) ++report.crease_vertices;
  }
  report.boundary_vertices = static_cast<std::size_t>(
      std::count_if(graph.on_boundary.begin(), graph.on_boundary.end(), [](std::uint8_t b) { return b != 0; }));
  const std::vector<Index> band = surface_detail::interior_band(mesh, graph, options.interior_layers, pinned);
  report.interior_vertices = band.size();
  const auto boundary_classes = surface_detail::colour_classes(boundary, mesh, graph.vertex_hexes);
  const auto interior_classes = surface_detail::colour_classes(band, mesh, graph.vertex_hexes);
  report.colours = boundary_classes.size() + interior_classes.size();

  // Mean boundary edge length: the scale of the convergence test.
  double edge_sum = 0;
  std::size_t edge_count = 0;
  for (Index v = 0; v < nv; ++v)
    for (Index k = graph.boundary_neighbours.offsets[v]; k < graph.boundary_neighbours.offsets[v + 1]; ++k)
      if (graph.boundary_neighbours.ids[k] > v) {
        edge_sum += (mesh.points[graph.boundary_neighbours.ids[k]] - mesh.points[v]).norm();
        ++edge_count;
      }
  const double mean_edge = edge_count > 0 ? edge_sum / static_cast<double>(edge_count) : 0.0;

  // The projection phase's hard floors: no new inverted hex or boundary quad.
  MoveContext ctx{mesh,
                  graph,
                  field,
                  options.min_hex_sj,
                  options.min_quad_sj,
                  0.0,
                  options.max_halvings,
                  options.level_tolerance * field.value_range(),
                  options.projection_reach,
                  options.guard_hexes,
                  nullptr};
  const std::vector<std::int8_t> codes = options.planar.empty() ? std::vector<std::int8_t>{} : plane_codes(mesh, graph, options.planar);
  ctx.planar = &codes;
  // Only the boundary and band vertices ever move: where they start and where each iteration
  // found them are kept for them alone (three copies of every point were 39 MB on cthead h 2,
  // and the stage's peak).
  std::vector<Index> movable = boundary;
  movable.insert(movable.end(), band.begin(), band.end());
  const auto take = [&](std::vector<Vec3>& x) {  // into x's own buffer: no allocation per iteration
    x.resize(movable.size());
    for (std::size_t i = 0; i < movable.size(); ++i) x[i] = mesh.points[movable[i]];
  };
  const auto farthest = [&](const std::vector<Vec3>& from) {  // the largest distance moved since `from`
    double d = 0;
    for (std::size_t i = 0; i < movable.size(); ++i) d = std::max(d, (mesh.points[movable[i]] - from[i]).norm());
    return d;
  };
  std::vector<Vec3> start;
  take(start);
  std::vector<double> curvature(options.normal_weight > 0 ? static_cast<std::size_t>(nv) : 0, 0.0);
  std::vector<MoveOutcome> outcome(static_cast<std::size_t>(nv), MoveOutcome::none);
  std::vector<Vec3> before_iteration;

  // Onto the isosurface first: the relaxation's guarantees start from the projected mesh.
  sweep(boundary_classes, outcome, report,
        [&](Index v) { return surface_detail::move_boundary_vertex(ctx, v, Vec3::Zero()); });
  report.projected = quality_of(mesh, graph);
  ctx.quad_hard_floor = report.projected.quad_sj_min;
  const std::vector<Vec3> anchor = mesh.points;
  std::vector<double> travel(static_cast<std::size_t>(nv), 0.0);
  for (Index v : boundary) travel[v] = options.max_travel * surface_detail::mean_boundary_edge(ctx, v);
  ctx.anchor = &anchor;
  ctx.travel = &travel;

  // The stall test's history (stall_iterations): the boundary quads after each iteration.
  std::vector<QuadSummary> standing;
  std::size_t lowest = std::numeric_limits<std::size_t>::max();
  int since_low = 0;
  for (int it = 0; it < options.iterations; ++it) {
    take(before_iteration);
    // Curvatures from one snapshot (Jacobi), so every vertex sees the same H field.
    if (options.normal_weight > 0)
      tbb::parallel_for(std::size_t{0}, boundary.size(), [&](std::size_t i) {
        const Index v = boundary[i];
        curvature[v] = surface_detail::quad_umbrella(ctx, v).dot(surface_detail::outward_normal(ctx, v));
      });
    sweep(boundary_classes, outcome, report, [&](Index v) {
      const Vec3 step = graph.on_crease[v] ? Vec3::Zero()
                                           : surface_detail::boundary_step(ctx, v, curvature, options.tangential_weight,
                                                                           options.normal_weight);
      return surface_detail::move_boundary_vertex(ctx, v, step);
    });
    for (int s = 0; s < options.interior_sweeps; ++s)
      sweep(interior_classes, outcome, report, [&](Index v) {
        return surface_detail::move_interior_vertex(ctx, v, surface_detail::interior_step(ctx, v, options.interior_weight));
      });
    report.iterations = it + 1;
    const double moved = farthest(before_iteration);
    if (moved <= options.convergence * mean_edge) {
      report.converged = true;
      break;
    }
    if (options.stall_iterations > 0) {
      standing.push_back(summarize_quads(mesh, graph.quads));
      since_low = standing.back().below < lowest ? 0 : since_low + 1;
      lowest = std::min(lowest, standing.back().below);
      const std::size_t k = static_cast<std::size_t>(options.stall_iterations);
      if (since_low >= options.stall_iterations && standing.size() > k &&
          standing.back().mean < standing[standing.size() - 1 - k].mean + options.stall_gain) {
        report.stalled = true;
        break;
      }
    }
  }
  // Not needed past the relaxation (the max–min passes hold their own per-vertex normals).
  std::vector<Vec3>().swap(before_iteration);
  std::vector<QuadSummary>().swap(standing);

  std::vector<Index> sliding;  // features stay; folds that merely look like creases unfold
  std::vector<std::uint8_t> on_isosurface(static_cast<std::size_t>(nv), 0);
  for (Index v : boundary) {
    if (!graph.on_feature[v]) sliding.push_back(v);
    on_isosurface[v] = !surface_detail::in_box_face(ctx, v);
  }
  worst_quad_passes(ctx, sliding, on_isosurface, options, report);

  // Whatever the iterations did (or if there were none), end on the isosurface where allowed.
  sweep(boundary_classes, outcome, report,
        [&](Index v) { return surface_detail::move_boundary_vertex(ctx, v, Vec3::Zero()); });

  const double guarantee = kSurfaceGuarantee * field.value_range();
  for (Index v : boundary) {
    if (surface_detail::in_box_face(ctx, v)) continue;  // not on the isosurface
    const double l = std::abs(field.level(mesh.points[v]));
    report.max_level = std::max(report.max_level, l);
    if (l > guarantee) ++report.off_surface;
  }
  report.max_level_relative = report.max_level / field.value_range();
  report.max_displacement = farthest(start);
  report.after = quality_of(mesh, graph);
  return report;
}

}  // namespace isohex
