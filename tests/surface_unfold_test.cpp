// The max–min pass of surface smoothing: folded boundary quads unfold on the isosurface, and
// the domain box's faces are smoothed in their planes (rims along the isosurface).
#include "isohex/contour/dual_contour.hpp"
#include "isohex/contour/region.hpp"
#include "isohex/mesh/generate.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/surface/smooth_region.hpp"
#include "isohex/surface/smooth_surface.hpp"
#include "surface_support.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace isohex;

namespace {

const Volume& sphere_volume() {
  static const Volume v = test::sampled(Shape::sphere(Vec3::Zero(), 1.0), 48);
  return v;
}

double quad_sj(const HexMesh& m, const Quad& q) {
  return quad_scaled_jacobian({m.points[q[0]], m.points[q[1]], m.points[q[2]], m.points[q[3]]});
}

double min_quad_sj(const HexMesh& m) {
  double lo = 1;
  for (const Quad& q : boundary_quads(m)) lo = std::min(lo, quad_sj(m, q));
  return lo;
}

// A ball on the sphere's isosurface with one boundary vertex dragged along the surface past
// its neighbour: the quads around it fold (negative scaled Jacobian).
HexMesh folded_ball(const IsoField& field) {
  HexMesh m = ball_mesh(8, 1.0);
  test::jitter_boundary(m, field, 0.0, 1);  // onto the trilinear isosurface
  const std::vector<Quad> quads = boundary_quads(m);
  const Incidence vq = vertex_cells(quads, m.num_vertices());
  // A valence-4 vertex near the middle of a cube face of the mapping (+z side).
  Index v = -1;
  for (Index w = 0; w < m.num_vertices(); ++w)
    if (vq.count(w) == 4 && m.points[w].z() > 0.9 && (v < 0 || m.points[w].z() > m.points[v].z())) v = w;
  const Quad& q = quads[vq.ids[vq.offsets[v]]];
  Index w = q[0] == v ? q[1] : q[0];
  Vec3 y = m.points[v] + 1.6 * (m.points[w] - m.points[v]);
  EXPECT_TRUE(field.project(y, 1.0, 1e-9 * field.value_range()));
  m.points[v] = y;
  return m;
}

}  // namespace

TEST(SurfaceUnfold, FoldedQuadsUnfoldOnTheIsosurface) {
  const IsoField field(sphere_volume(), 0, Inside::below);
  const HexMesh folded = folded_ball(field);
  ASSERT_LT(min_quad_sj(folded), 0.0);

  SurfaceSmoothingOptions o;
  o.iterations = 0;        // the max–min pass alone
  o.guard_hexes = false;   // as before a pillow
  o.worst_passes = 0;
  HexMesh without = folded;
  smooth_surface(without, field, o);
  EXPECT_LT(min_quad_sj(without), 0.0) << "nothing else unfolds it";

  o.worst_passes = 40;
  HexMesh m = folded;
  const SurfaceSmoothingReport r = smooth_surface(m, field, o);
  EXPECT_GT(r.worst_moves, 0u);
  EXPECT_GT(r.after.quad_sj_min, 0.5);  // measured 0.80 (the clean ball: 0.87)
  EXPECT_EQ(r.after.quads_below, 0u);
  EXPECT_LE(r.max_level_relative, 1e-6);
  // No quad turned inward (Verdict's value alone cannot tell): on a sphere, outward is radial.
  for (const Quad& q : boundary_quads(m)) {
    const auto& p = m.points;
    const Vec3 n = (p[q[2]] - p[q[0]]).cross(p[q[3]] - p[q[1]]);
    EXPECT_GT(n.dot(p[q[0]] + p[q[1]] + p[q[2]] + p[q[3]]), 0.0);
  }

  // With the relaxation as well (the pipeline's setting) the fold goes too.
  o.iterations = 30;
  HexMesh both = folded;
  EXPECT_GT(smooth_surface(both, field, o).after.quad_sj_min, 0.5);
}

TEST(SurfaceUnfold, GuardedHexesKeepTheirFloors) {
  const IsoField field(sphere_volume(), 0, Inside::below);
  HexMesh m = folded_ball(field);
  const std::vector<double> before = scaled_jacobians(m);
  SurfaceSmoothingOptions o;
  o.iterations = 0;
  const SurfaceSmoothingReport r = smooth_surface(m, field, o);  // guard_hexes: on
  EXPECT_GT(r.after.quad_sj_min, r.before.quad_sj_min);
  const std::vector<double> after = scaled_jacobians(m);
  for (std::size_t h = 0; h < before.size(); ++h) {
    if (before[h] >= 0.2) EXPECT_GE(after[h], 0.2) << "hex " << h;
    if (before[h] >= 0) EXPECT_GE(after[h], 0.0) << "hex " << h;
    if (before[h] < 0) EXPECT_GE(after[h], before[h]) << "hex " << h;
  }
}

TEST(SurfaceUnfold, BoxFacesSlideInTheirPlanesAndRimsOnTheIsosurface) {
  // A ball of radius 1.25 cut by the box [-1, 1]³: six flat disks closed by the box faces.
  const Volume vol = sample(Shape::sphere(Vec3::Zero(), 1.25), grid_from_dims({Vec3::Constant(-1), Vec3::Constant(1)}, {33, 33, 33}));
  contour::RegionSpec spec;
  spec.isovalue = 0;
  spec.inside = Inside::below;
  const contour::Region region = contour::make_region(vol, spec);
  contour::ExtractOptions eo;
  eo.resolution = 16;
  contour::ExtractResult ex = contour::extract_hex_mesh(region, eo);

  // Shake the vertices inside the box faces within their planes.
  const std::vector<std::int8_t> axis = box_face_axes(ex.mesh, region.domain.lo, region.domain.hi);
  const std::vector<Quad> quads = boundary_quads(ex.mesh);
  std::vector<std::uint8_t> in_face(ex.mesh.points.size(), 0), rim(ex.mesh.points.size(), 0);
  for (std::size_t v = 0; v < axis.size(); ++v) in_face[v] = axis[v] >= 0 && ex.vertex_place[v] == contour::kBoxVertex;
  for (const Quad& q : quads)
    for (Index v : q)
      for (Index w : q)
        if (in_face[v] && ex.mesh.points[w][axis[v]] != ex.mesh.points[v][axis[v]]) rim[v] = 1;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.04, 0.04);  // a third of a cell
  std::size_t shaken = 0, rims = 0;
  for (std::size_t v = 0; v < axis.size(); ++v) {
    rims += rim[v];
    if (!in_face[v] || rim[v]) continue;
    for (int a = 0; a < 3; ++a)
      if (a != axis[v]) ex.mesh.points[v][a] += u(rng);
    ++shaken;
  }
  ASSERT_GT(shaken, 50u);
  ASSERT_GT(rims, 50u);
  const HexMesh start = ex.mesh;
  double face_before = 1;
  for (const Quad& q : quads)
    if (in_face[q[0]] && in_face[q[1]] && in_face[q[2]] && in_face[q[3]]) face_before = std::min(face_before, quad_sj(start, q));

  SurfaceSmoothingOptions o;
  o.guard_hexes = false;
  const auto reports = smooth_region_surfaces(region, ex, o);
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0].off_surface, 0u);

  const IsoField& field = *region.surfaces[0].field();
  double face_after = 1;
  std::size_t moved_face = 0, moved_rim = 0;
  for (std::size_t v = 0; v < axis.size(); ++v) {
    const Vec3& p0 = start.points[v];
    const Vec3& p1 = ex.mesh.points[v];
    if (ex.vertex_place[v] == contour::kBoxVertex && axis[v] < 0) EXPECT_EQ(p1, p0) << "box edge vertex " << v;
    if (!in_face[v]) continue;
    EXPECT_EQ(p1[axis[v]], p0[axis[v]]) << "left its plane: " << v;
    if (rim[v]) EXPECT_LE(std::abs(field.level(p1)), 1e-6 * field.value_range()) << "rim vertex off the isosurface: " << v;
    (rim[v] ? moved_rim : moved_face) += p1 != p0;
  }
  // A face quad with three vertices on the rim has an angle near 180° at the middle one
  // whatever the sliding (the rim is convex): those limit the minimum; the others get good.
  double face_inner_after = 1, face_inner_before = 1;
  for (const Quad& q : quads)
    if (in_face[q[0]] && in_face[q[1]] && in_face[q[2]] && in_face[q[3]]) {
      face_after = std::min(face_after, quad_sj(ex.mesh, q));
      if (rim[q[0]] + rim[q[1]] + rim[q[2]] + rim[q[3]] <= 2) {
        face_inner_after = std::min(face_inner_after, quad_sj(ex.mesh, q));
        face_inner_before = std::min(face_inner_before, quad_sj(start, q));
      }
    }
  EXPECT_GT(moved_face, shaken / 2);
  EXPECT_GT(moved_rim, 0u);
  EXPECT_GT(face_after, face_before + 0.05) << face_before << " -> " << face_after;  // measured 0.105 -> 0.166
  EXPECT_GT(face_inner_after, 0.5) << face_inner_before << " -> " << face_inner_after;
}
