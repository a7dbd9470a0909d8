// The dual-contouring mesher on sampled implicit shapes: valid closed meshes of the right
// topology and volume, boundary on the isosurface, regions, and thread-count bit identity.
#include "isohex/contour/dual_contour.hpp"
#include "isohex/error.hpp"
#include "isohex/mesh/validate.hpp"
#include "isohex/quality/hex_quality.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <numbers>

namespace isohex::contour {
namespace {

constexpr double kPi = std::numbers::pi;

struct Case {
  Volume volume;
  Region region;
};

// The shape's signed distance sampled at `spacing`, meshed as {distance < 0}.
Volume sampled(const std::string& expr, double spacing) {
  const Shape s = parse_shape(expr);
  return sample(s, grid_from_cell_size(sampling_bounds(s), spacing));
}

ExtractResult mesh(const Region& r, double h) {
  ExtractOptions opt;
  opt.cell_size = h;
  return extract_hex_mesh(r, opt);
}

double total_volume(const HexMesh& m) {
  double v = 0;
  for (Index h = 0; h < m.num_hexes(); ++h) v += volume(m.corners(h));
  return v;
}

RegionSpec below(double iso) {
  RegionSpec spec;
  spec.isovalue = iso;
  spec.inside = Inside::below;
  return spec;
}

TEST(ContourShapes, SphereIsAClosedBallOnTheIsosurface) {
  const Volume v = sampled("sphere(0,0,0, 1)", 0.05);
  const Region r = make_region(v, below(0));
  const ExtractResult out = mesh(r, 0.1);
  const ValidationReport check = validate(out.mesh);
  EXPECT_TRUE(check.valid());
  EXPECT_EQ(check.num_boundary_components, 1u);
  EXPECT_EQ(check.euler_characteristic, 2);
  EXPECT_NEAR(total_volume(out.mesh), 4.0 / 3.0 * kPi, 0.01 * 4.0 / 3.0 * kPi);
  const SurfaceDistance d = surface_distance(r, out.mesh, out.vertex_place);
  EXPECT_EQ(d.checked, check.num_boundary_vertices);
  EXPECT_EQ(d.box_vertices, 0u);
  EXPECT_LE(d.max_relative, 1e-6);
  const std::vector<double> sj = scaled_jacobians(out.mesh);
  EXPECT_GT(*std::min_element(sj.begin(), sj.end()), -1.0);
}

TEST(ContourShapes, TorusHasGenusOne) {
  for (Interpolation interp : {Interpolation::trilinear, Interpolation::cubic}) {
    const Volume v = sampled("torus(0,0,0, 1, 0.4)", 0.05);
    RegionSpec spec = below(0);
    spec.interpolation = interp;
    const Region r = make_region(v, spec);
    const ExtractResult out = mesh(r, 0.08);
    const ValidationReport check = validate(out.mesh);
    EXPECT_TRUE(check.valid());
    EXPECT_EQ(check.num_boundary_components, 1u);
    EXPECT_EQ(check.euler_characteristic, 0);
    const double exact = 2 * kPi * kPi * 1.0 * 0.4 * 0.4;
    EXPECT_NEAR(total_volume(out.mesh), exact, 0.01 * exact);
    EXPECT_LE(surface_distance(r, out.mesh, out.vertex_place).max_relative, 1e-6);
  }
}

TEST(ContourShapes, SameMeshBitForBitForAnyThreadCount) {
  const Volume v = sampled("difference(box(-1,-1,-1, 1,1,1), sphere(0.3,0.2,0.1, 1.1))", 0.04);
  const Region r = make_region(v, below(0));
  ExtractResult one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = mesh(r, 0.07);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = mesh(r, 0.07);
  }
  ASSERT_GT(one.mesh.num_hexes(), 1000);
  ASSERT_EQ(one.mesh.points.size(), two.mesh.points.size());
  EXPECT_EQ(0, std::memcmp(one.mesh.points.data(), two.mesh.points.data(), one.mesh.points.size() * sizeof(Vec3)));
  EXPECT_EQ(one.mesh.hexes, two.mesh.hexes);
  EXPECT_EQ(one.vertex_place, two.vertex_place);
}

TEST(ContourShapes, SolidCutByTheBoxHasBoxVerticesOnTheFaces) {
  // A sphere larger than the sampled box: the boundary is partly the box's faces.
  Volume v = sampled("sphere(0,0,0, 1)", 0.05);
  const Region r = make_region(v, below(0.3));  // distance < 0.3: radius 1.3 > the box half-width 1.1
  const ExtractResult out = mesh(r, 0.1);
  const ValidationReport check = validate(out.mesh);
  EXPECT_TRUE(check.valid());
  EXPECT_EQ(check.euler_characteristic, 2);
  const SurfaceDistance d = surface_distance(r, out.mesh, out.vertex_place);
  EXPECT_GT(d.box_vertices, 0u);
  EXPECT_EQ(d.checked + d.box_vertices, check.num_boundary_vertices);
  EXPECT_LE(d.max_relative, 1e-6);
  for (std::size_t i = 0; i < out.mesh.points.size(); ++i) {
    if (out.vertex_place[i] != kBoxVertex) continue;
    const Vec3& p = out.mesh.points[i];
    const double face = std::min((p - r.domain.lo).cwiseAbs().minCoeff(), (p - r.domain.hi).cwiseAbs().minCoeff());
    EXPECT_LE(face, 1e-12);
  }
}

TEST(ContourRegions, ShellBetweenTwoIsovaluesHasTwoBoundaries) {
  const Volume v = sampled("sphere(0,0,0, 1)", 0.05);
  RegionSpec spec;
  spec.kind = RegionKind::between;
  spec.isovalue = -0.5;  // radius 0.5
  spec.isovalue2 = 0;    // radius 1
  const Region r = make_region(v, spec);
  const ExtractResult out = mesh(r, 0.08);
  const ValidationReport check = validate(out.mesh);
  EXPECT_TRUE(check.valid());
  EXPECT_EQ(check.num_boundary_components, 2u);
  EXPECT_EQ(check.euler_characteristic, 4);
  const double exact = 4.0 / 3.0 * kPi * (1 - 0.125);
  EXPECT_NEAR(total_volume(out.mesh), exact, 0.01 * exact);
  const SurfaceDistance d = surface_distance(r, out.mesh, out.vertex_place);
  EXPECT_EQ(d.checked, check.num_boundary_vertices);
  EXPECT_LE(d.max_relative, 1e-6);
  // Both surfaces carry vertices.
  EXPECT_GT(std::count(out.vertex_place.begin(), out.vertex_place.end(), 0), 100);
  EXPECT_GT(std::count(out.vertex_place.begin(), out.vertex_place.end(), 1), 100);
}

TEST(ContourRegions, OutsideUpToASphereEmbedsTheSolid) {
  const Volume v = sampled("box(-0.5,-0.5,-0.5, 0.5,0.5,0.5)", 0.05);
  RegionSpec spec = below(0);
  spec.kind = RegionKind::outside;
  spec.outer = parse_outer("sphere:0,0,0,1.5");
  const Region r = make_region(v, spec);
  const ExtractResult out = mesh(r, 0.1);
  const ValidationReport check = validate(out.mesh);
  EXPECT_TRUE(check.valid());
  EXPECT_EQ(check.num_boundary_components, 2u);
  const double exact = 4.0 / 3.0 * kPi * 1.5 * 1.5 * 1.5 - 1.0;
  EXPECT_NEAR(total_volume(out.mesh), exact, 0.01 * exact);
  const SurfaceDistance d = surface_distance(r, out.mesh, out.vertex_place);
  EXPECT_EQ(d.checked, check.num_boundary_vertices);
  EXPECT_LE(d.max_relative, 1e-6);
  for (std::size_t i = 0; i < out.mesh.points.size(); ++i)
    if (out.vertex_place[i] == 1) EXPECT_NEAR(out.mesh.points[i].norm(), 1.5, 1e-9);
}

TEST(ContourRegions, OuterBoundaryParsing) {
  EXPECT_EQ(parse_outer("sphere:1,2,3,4").radius, 4);
  EXPECT_EQ(parse_outer("box:0,0,0,1,2,3").box.hi, Vec3(1, 2, 3));
  EXPECT_THROW(parse_outer("sphere:1,2,3"), Error);
  EXPECT_THROW(parse_outer("box:0,0,0,-1,2,3"), Error);
  EXPECT_THROW(parse_outer("cylinder:1"), Error);
}

}  // namespace
}  // namespace isohex::contour
