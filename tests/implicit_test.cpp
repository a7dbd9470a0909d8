// Implicit shapes: exact distances, CSG signs, bounds, the parser (round trip and error
// columns) and sampling.
#include "isohex/error.hpp"
#include "isohex/volume/implicit.hpp"
#include "isohex/volume/volume_io.hpp"
#include "test_support.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

namespace isohex {
namespace {

constexpr double kTol = 1e-12;

std::string error_of(std::string_view text) {
  try {
    parse_shape(text);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

double at(const Shape& s, double x, double y, double z) { return evaluate(s, Vec3(x, y, z)); }

TEST(Implicit, SphereDistances) {
  const Shape s = Shape::sphere(Vec3(1, 2, 3), 2);
  EXPECT_NEAR(at(s, 1, 2, 3), -2, kTol);
  EXPECT_NEAR(at(s, 1, 2, 6), 1, kTol);
  EXPECT_NEAR(at(s, 1 + 3, 2 + 4, 3), 3, kTol);
  EXPECT_NEAR(at(s, 2, 2, 3), -1, kTol);
}

TEST(Implicit, BoxDistances) {
  const Shape b = Shape::box(Vec3(-1, -2, -3), Vec3(1, 2, 3));
  EXPECT_NEAR(at(b, 0, 0, 0), -1, kTol);        // nearest face x = ±1
  EXPECT_NEAR(at(b, 0, 1.5, 0), -0.5, kTol);    // nearest face y = 2
  EXPECT_NEAR(at(b, 2, 0, 0), 1, kTol);         // face
  EXPECT_NEAR(at(b, 2, 3, 0), std::sqrt(2.0), kTol);  // edge
  EXPECT_NEAR(at(b, -2, 3, -5), std::sqrt(6.0), kTol);  // corner: offsets (1, 1, 2)
  EXPECT_NEAR(at(b, 1, 2, 3), 0, kTol);
}

TEST(Implicit, CylinderDistances) {
  const Shape c = Shape::cylinder(Vec3(0, 0, 0), Vec3(0, 0, 4), 1);
  EXPECT_NEAR(at(c, 0, 0, 2), -1, kTol);
  EXPECT_NEAR(at(c, 0.5, 0, 3.9), -0.1, 1e-12);  // the cap is nearer than the side
  EXPECT_NEAR(at(c, 3, 0, 2), 2, kTol);
  EXPECT_NEAR(at(c, 0, 0, 6), 2, kTol);
  EXPECT_NEAR(at(c, 0, 0.5, -1), 1, kTol);
  EXPECT_NEAR(at(c, 2, 0, 5), std::sqrt(2.0), kTol);  // beyond the rim
  // A tilted axis: (0,0,0) to (2,2,0); from its middle straight up by 3.
  const Shape t = Shape::cylinder(Vec3(0, 0, 0), Vec3(2, 2, 0), 0.5);
  EXPECT_NEAR(at(t, 1, 1, 3), 2.5, kTol);
  EXPECT_NEAR(at(t, -1, -1, 0), std::sqrt(2.0), kTol);  // beyond the first cap, on the axis
}

TEST(Implicit, TorusDistances) {
  const Shape t = Shape::torus(Vec3(0, 0, 0), Vec3(0, 0, 1), 2, 0.5);
  EXPECT_NEAR(at(t, 2, 0, 0), -0.5, kTol);
  EXPECT_NEAR(at(t, 0, 0, 0), 1.5, kTol);
  EXPECT_NEAR(at(t, 3, 0, 0), 0.5, kTol);
  EXPECT_NEAR(at(t, 0, 2, 1), 0.5, kTol);
  EXPECT_NEAR(at(t, 0, 0, 3), std::sqrt(13.0) - 0.5, kTol);
  // Around x, centred at (1, 1, 1), axis given unnormalised.
  const Shape u = Shape::torus(Vec3(1, 1, 1), Vec3(5, 0, 0), 2, 0.5);
  EXPECT_NEAR(at(u, 1, 3, 1), -0.5, kTol);
  EXPECT_NEAR(at(u, 1, 1, 3), -0.5, kTol);
  EXPECT_NEAR(at(u, 3, 1, 1), std::sqrt(8.0) - 0.5, kTol);
}

TEST(Implicit, PlaneDistances) {
  const Shape p = Shape::plane(Vec3(0, 0, 1), Vec3(0, 0, 2));
  EXPECT_NEAR(at(p, 5, 5, 3), 2, kTol);
  EXPECT_NEAR(at(p, 0, 0, 0), -1, kTol);
  const Shape q = Shape::plane(Vec3(0, 0, 0), Vec3(1, 1, 0));
  EXPECT_NEAR(at(q, 1, 1, 7), std::sqrt(2.0), kTol);
  EXPECT_NEAR(at(q, -1, 0, 0), -std::sqrt(0.5), kTol);
}

TEST(Implicit, CsgSignsAndValues) {
  const Shape hollow = parse_shape("difference(box(-1,-1,-1, 1,1,1), sphere(0,0,0, 1.2))");
  EXPECT_GT(at(hollow, 0, 0, 0), 0);            // carved out
  EXPECT_LT(at(hollow, 0.95, 0.95, 0.95), 0);   // a corner remains
  EXPECT_GT(at(hollow, 1.5, 0, 0), 0);          // outside the box
  EXPECT_GT(at(hollow, 1, 0, 0), 0);            // face centre lies inside the sphere: removed
  EXPECT_NEAR(at(hollow, 0, 0, 0), 1.2, kTol);  // max(-1, 1.2)

  const Shape ring = parse_shape("union(sphere(0,0,0,1), torus(0,0,0, 2, 0.5))");
  EXPECT_LT(at(ring, 0, 0, 0), 0);
  EXPECT_LT(at(ring, 2, 0, 0), 0);
  EXPECT_GT(at(ring, 1.25, 0, 0), 0);  // between the ball and the ring
  EXPECT_NEAR(at(ring, 0, 0, 5), 4, kTol);  // outside a union the min is exact

  const Shape cap = parse_shape("intersection(sphere(0,0,0,1), plane(0,0,0.5, 0,0,1))");
  EXPECT_LT(at(cap, 0, 0, 0), 0);
  EXPECT_GT(at(cap, 0, 0, 0.75), 0);  // in the ball, above the plane
  EXPECT_GT(at(cap, 0, 0, -1.5), 0);  // below the ball
  EXPECT_NEAR(at(cap, 0, 0, 0.25), -0.25, kTol);  // inside an intersection the max is exact

  // n-ary: the first minus all others.
  const Shape two_holes = parse_shape("difference(box(-3,-1,-1, 3,1,1), sphere(-2,0,0,0.5), sphere(2,0,0,0.5))");
  EXPECT_GT(at(two_holes, -2, 0, 0), 0);
  EXPECT_GT(at(two_holes, 2, 0, 0), 0);
  EXPECT_LT(at(two_holes, 0, 0, 0), 0);
}

void expect_box(const Aabb& b, const Vec3& lo, const Vec3& hi) {
  EXPECT_TRUE(b.lo.isApprox(lo, 1e-12) || (b.lo - lo).norm() < 1e-12) << b.lo.transpose() << " vs " << lo.transpose();
  EXPECT_TRUE(b.hi.isApprox(hi, 1e-12) || (b.hi - hi).norm() < 1e-12) << b.hi.transpose() << " vs " << hi.transpose();
}

TEST(Implicit, Bounds) {
  expect_box(bounds(Shape::sphere(Vec3(1, 2, 3), 2)), Vec3(-1, 0, 1), Vec3(3, 4, 5));
  expect_box(bounds(Shape::cylinder(Vec3(0, 0, 0), Vec3(0, 0, 4), 1)), Vec3(-1, -1, 0), Vec3(1, 1, 4));
  const double e = 0.5 * std::sqrt(0.5);  // radius 0.5 disc normal to (1,1,0)/√2
  expect_box(bounds(Shape::cylinder(Vec3(0, 0, 0), Vec3(2, 2, 0), 0.5)), Vec3(-e, -e, -0.5), Vec3(2 + e, 2 + e, 0.5));
  expect_box(bounds(Shape::torus(Vec3(0, 0, 0), Vec3(0, 0, 1), 2, 0.5)), Vec3(-2.5, -2.5, -0.5), Vec3(2.5, 2.5, 0.5));
  const Aabb half = bounds(Shape::plane(Vec3(0, 0, 0.5), Vec3(0, 0, 3)));
  EXPECT_FALSE(half.is_finite());
  EXPECT_EQ(half.hi.z(), 0.5);
  EXPECT_TRUE(std::isinf(half.lo.z()) && std::isinf(half.hi.x()));
  expect_box(bounds(parse_shape("intersection(sphere(0,0,0,1), plane(0,0,0.5, 0,0,1))")), Vec3(-1, -1, -1),
             Vec3(1, 1, 0.5));
  expect_box(bounds(parse_shape("union(sphere(0,0,0,1), sphere(3,0,0,1))")), Vec3(-1, -1, -1), Vec3(4, 1, 1));
  expect_box(bounds(parse_shape("difference(sphere(0,0,0,1), sphere(3,0,0,5))")), Vec3(-1, -1, -1), Vec3(1, 1, 1));
  // Every surface point sampled lies in the box.
  const Shape t = Shape::torus(Vec3(0.3, -1, 2), Vec3(1, 2, 3), 2, 0.4);
  const Aabb tb = bounds(t);
  const Vec3 n = Vec3(1, 2, 3).normalized(), u = n.unitOrthogonal(), w = n.cross(u);
  for (int i = 0; i < 64; ++i)
    for (int j = 0; j < 64; ++j) {
      const double a = i * M_PI / 32, b = j * M_PI / 32;
      const Vec3 p = Vec3(0.3, -1, 2) + (2 + 0.4 * std::cos(b)) * (std::cos(a) * u + std::sin(a) * w) + 0.4 * std::sin(b) * n;
      ASSERT_NEAR(evaluate(t, p), 0, 1e-12);
      ASSERT_TRUE((p.array() >= tb.lo.array() - 1e-12).all() && (p.array() <= tb.hi.array() + 1e-12).all());
    }
}

TEST(Implicit, ParserReadsEveryPrimitive) {
  EXPECT_EQ(parse_shape(" sphere ( 1 , -2.5e0 , +3 , 0.25 ) "), Shape::sphere(Vec3(1, -2.5, 3), 0.25));
  EXPECT_EQ(parse_shape("box(-1,-1,-1,1,1,1)"), Shape::box(Vec3(-1, -1, -1), Vec3(1, 1, 1)));
  EXPECT_EQ(parse_shape("cylinder(0,0,0, 0,0,4, 1)"), Shape::cylinder(Vec3(0, 0, 0), Vec3(0, 0, 4), 1));
  EXPECT_EQ(parse_shape("torus(0,0,0, 2, .5)"), Shape::torus(Vec3(0, 0, 0), Vec3(0, 0, 1), 2, 0.5));
  EXPECT_EQ(parse_shape("torus(0,0,0, 1,0,0, 2, 0.5)"), Shape::torus(Vec3(0, 0, 0), Vec3(1, 0, 0), 2, 0.5));
  EXPECT_EQ(parse_shape("plane(0,0,1, 0,0,1)"), Shape::plane(Vec3(0, 0, 1), Vec3(0, 0, 1)));
  const Shape u = parse_shape("union(sphere(0,0,0,1), torus(0,0,0, 2, 0.5))");
  ASSERT_TRUE(std::holds_alternative<Csg>(u.node));
  EXPECT_EQ(std::get<Csg>(u.node).op, CsgOp::unite);
  EXPECT_EQ(std::get<Csg>(u.node).operands.size(), 2u);
}

TEST(Implicit, ParserRoundTripsExactly) {
  std::mt19937 g(3);
  std::uniform_real_distribution<double> any(-10, 10), pos(0.1, 3);
  auto v = [&] { return Vec3(any(g), any(g), any(g)); };
  for (int trial = 0; trial < 50; ++trial) {
    const Vec3 lo = v();
    const double major = pos(g) + 1;
    std::vector<Shape> prims = {
        Shape::sphere(v(), pos(g)),
        Shape::box(lo, lo + Vec3(pos(g), pos(g), pos(g))),
        Shape::cylinder(v(), v(), pos(g)),
        Shape::torus(v(), Vec3(0, 0, 1), major, major * 0.3),
        Shape::torus(v(), v(), major, major * 0.9),
        Shape::plane(v(), v()),
    };
    for (const Shape& s : prims) {
      const std::string text = to_shape_string(s);
      ASSERT_EQ(parse_shape(text), s) << text;
    }
    const Shape tree = Shape::subtract({Shape::unite({prims[0], prims[1], prims[2]}), Shape::intersect({prims[3], prims[5]}),
                                        prims[4]});
    const std::string text = to_shape_string(tree);
    ASSERT_EQ(parse_shape(text), tree) << text;
    ASSERT_EQ(to_shape_string(parse_shape(text)), text);
  }
  EXPECT_EQ(to_shape_string(parse_shape("difference( box(-1,-1,-1,1,1,1) ,sphere(0,0,0,1.2))")),
            "difference(box(-1, -1, -1, 1, 1, 1), sphere(0, 0, 0, 1.2))");
}

TEST(Implicit, ParserErrorsNameTheColumn) {
  const std::string known = "sphere, box, cylinder, torus, plane, union, intersection, difference";
  EXPECT_EQ(error_of("sphere(0,0,0 1)"), "shape expression, column 14: expected ',' after the centre z, found '1'");
  const std::string hollow = "difference(box(-1,-1,-1, 1,1,1), sphere(0,0,0, 1.2 ))x";
  EXPECT_EQ(error_of("difference(box(-1,-1,-1, 1,1,1), sphere(0,0,0 1.2))"),
            "shape expression, column 47: expected ',' after the centre z, found '1.2'");
  EXPECT_EQ(error_of(hollow), "shape expression, column 54: unexpected 'x' after the end of the shape");
  EXPECT_EQ(error_of("sphere(0,0,0,1"), "shape expression, column 15: expected ')' after the radius, found the end");
  EXPECT_EQ(error_of("sphre(1)"), "shape expression, column 1: unknown shape 'sphre' (known: " + known + ")");
  EXPECT_EQ(error_of(""), "shape expression, column 1: expected a shape (" + known + "), found the end");
  EXPECT_EQ(error_of("sphere(0,0,0,-1)"), "shape expression, column 14: the radius of the sphere must be positive, found -1");
  EXPECT_EQ(error_of("sphere(0,0,0,abc)"),
            "shape expression, column 14: expected the radius of the sphere (a number), found 'abc'");
  EXPECT_EQ(error_of("sphere(0,0,0,1e999)"),
            "shape expression, column 14: expected the radius of the sphere (a number), found '1e999'");
  EXPECT_EQ(error_of("box(1,0,0, 0,1,1)"),
            "shape expression, column 12: the box's second corner x (0) must be above its first corner x (1)");
  EXPECT_EQ(error_of("cylinder(0,0,0, 0,0,0, 1)"), "shape expression, column 1: the cylinder's two ends coincide");
  EXPECT_EQ(error_of("torus(0,0,0, 1, 2)"),
            "shape expression, column 17: the torus's minor radius (2) must be below its major radius (1)");
  EXPECT_EQ(error_of("torus(0,0,0, 0,0,0, 2, 1)"), "shape expression, column 14: the torus axis is zero");
  EXPECT_EQ(error_of("torus(0,0,0, 2, -1)"),
            "shape expression, column 17: the minor radius of the torus must be positive, found -1");
  EXPECT_EQ(error_of("torus(0,0,0, 2, 1, 5)"),
            "shape expression, column 21: expected ',' after the axis z, found ')'");
  EXPECT_EQ(error_of("plane(0,0,0, 0,0,0)"), "shape expression, column 14: the plane's normal is zero");
  EXPECT_EQ(error_of("union(sphere(0,0,0,1))"), "shape expression, column 22: union needs at least two shapes, found one");
  EXPECT_EQ(error_of("union(sphere(0,0,0,1) sphere(1,1,1,1))"),
            "shape expression, column 23: expected ',' or ')' after shape 1 of the union, found 'sphere'");
  EXPECT_EQ(error_of("union sphere(0,0,0,1)"), "shape expression, column 7: expected '(' after 'union', found 'sphere'");
}

TEST(Implicit, SamplingMatchesEvaluate) {
  const Shape s = parse_shape("difference(box(-1,-1,-1, 1,1,1), sphere(0,0,0, 1.2))");
  const Aabb box = sampling_bounds(s);
  expect_box(box, Vec3::Constant(-1.2), Vec3::Constant(1.2));  // 10% of the side on each side
  const SampleGrid g = grid_from_dims(box, {17, 13, 11});
  const Volume v = sample(s, g);
  ASSERT_EQ(v.dims, (std::array<Index, 3>{17, 13, 11}));
  EXPECT_TRUE(v.origin.isApprox(box.lo));
  EXPECT_TRUE(v.max_corner().isApprox(box.hi));
  std::size_t negative = 0;
  for (Index k = 0; k < v.dims[2]; ++k)
    for (Index j = 0; j < v.dims[1]; ++j)
      for (Index i = 0; i < v.dims[0]; ++i) {
        ASSERT_EQ(v.at(i, j, k), static_cast<float>(evaluate(s, v.point(i, j, k))));
        negative += v.at(i, j, k) < 0;
      }
  EXPECT_GT(negative, 0u);
  // The outermost points lie outside (> 0), so the surface is closed inside the grid.
  for (Index k : {0, v.dims[2] - 1}) EXPECT_GT(v.at(3, 4, k), 0);

  const SampleGrid c = grid_from_cell_size(Aabb{Vec3(0, 0, 0), Vec3(1, 2, 0.95)}, 0.1);
  EXPECT_EQ(c.dims, (std::array<Index, 3>{11, 21, 11}));
  EXPECT_NEAR(c.origin.z() + 0.5 * (c.dims[2] - 1) * 0.1, 0.475, 1e-12);  // centred on the box
}

TEST(Implicit, SamplingErrors) {
  EXPECT_THROW(sampling_bounds(parse_shape("plane(0,0,0, 1,1,0)")), Error);
  EXPECT_THROW(sampling_bounds(parse_shape("intersection(sphere(0,0,0,1), sphere(5,0,0,1))")), Error);
  EXPECT_NO_THROW(sampling_bounds(parse_shape("intersection(box(-1,-1,-1,1,1,1), plane(0,0,0, 0,0,1))")));
  EXPECT_THROW(grid_from_dims(Aabb{Vec3::Zero(), Vec3::Ones()}, {1, 5, 5}), Error);
  EXPECT_THROW(grid_from_cell_size(Aabb{Vec3::Zero(), Vec3::Ones()}, 0), Error);
  EXPECT_THROW(sample(Shape::sphere(Vec3::Zero(), 1), SampleGrid{{2048, 2048, 2048}, Vec3::Ones(), Vec3::Zero()}), Error);
  EXPECT_THROW(Shape::unite({Shape::sphere(Vec3::Zero(), 1)}), Error);
  EXPECT_THROW(Shape::torus(Vec3::Zero(), Vec3(0, 0, 1), 1, 1), Error);
}

TEST(ShapeCli, WritesTheSampledShape) {
  const auto dir = test::scratch_dir();
  const std::string expr = "union(sphere(0,0,0,1), torus(0,0,0, 2, 0.5))";
  std::string out;
  ASSERT_EQ(test::run_cli(fmt::format("volume shape '{}' -o '{}' --dims 20 21 9", expr, (dir / "r.nrrd").string()), &out), 0)
      << out;
  EXPECT_NE(out.find("isovalue 0 (inside is below it)"), std::string::npos) << out;
  const Shape s = parse_shape(expr);
  EXPECT_TRUE(read_volume(dir / "r.nrrd").values == sample(s, grid_from_dims(sampling_bounds(s), {20, 21, 9})).values);

  ASSERT_EQ(test::run_cli(fmt::format("volume shape '{}' -o '{}' --cell-size 0.25 --bounds -3 -3 -1 3 3 1", expr,
                                      (dir / "r.vti").string()),
                          &out),
            0)
      << out;
  const Volume v = read_volume(dir / "r.vti");
  EXPECT_TRUE(v.values == sample(s, grid_from_cell_size(Aabb{Vec3(-3, -3, -1), Vec3(3, 3, 1)}, 0.25)).values);
  EXPECT_EQ(v.dims, (std::array<Index, 3>{25, 25, 9}));
}

TEST(ShapeCli, Errors) {
  const auto dir = test::scratch_dir();
  const std::string o = (dir / "x.nrrd").string();
  std::string out;
  EXPECT_EQ(test::run_cli(fmt::format("volume shape 'sphere(0,0,0 1)' -o '{}' --dims 4 4 4", o), &out), 2);
  EXPECT_NE(out.find("shape expression, column 14: expected ',' after the centre z"), std::string::npos) << out;
  EXPECT_EQ(test::run_cli(fmt::format("volume shape 'plane(0,0,0, 1,1,0)' -o '{}' --dims 4 4 4", o), &out), 2);
  EXPECT_NE(out.find("--bounds"), std::string::npos) << out;
  EXPECT_EQ(test::run_cli(fmt::format("volume shape 'sphere(0,0,0,1)' -o '{}'", o), &out), 2);
  EXPECT_NE(out.find("--dims NX NY NZ or --cell-size H"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(o));
}

}  // namespace
}  // namespace isohex
