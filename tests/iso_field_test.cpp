// IsoField: level sign convention, projection onto the isosurface, roots on segments.
#include "isohex/contour/iso_field.hpp"
#include "isohex/volume/implicit.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace isohex;

namespace {
Volume sphere_volume(double radius, double cell) {
  const Shape s = Shape::sphere(Vec3::Zero(), radius);
  return sample(s, grid_from_cell_size(sampling_bounds(s, 0.2), cell));
}
}  // namespace

TEST(IsoField, SignConventions) {
  const Volume v = sphere_volume(1.0, 0.1);
  const IsoField below(v, 0.0, Inside::below);
  EXPECT_GT(below.level(Vec3::Zero()), 0);        // centre is inside
  EXPECT_LT(below.level(Vec3(1.15, 0, 0)), 0);    // outside
  Vec3 g;
  below.level(Vec3(0.5, 0.02, 0.03), g);
  EXPECT_LT(g.x(), 0);  // the level grows inward
  const IsoField above(v, 0.0, Inside::above);
  EXPECT_DOUBLE_EQ(above.level(Vec3(0.3, 0.1, 0)), -below.level(Vec3(0.3, 0.1, 0)));
  EXPECT_EQ(interpolation_from_name("smooth-cubic"), Interpolation::smooth_cubic);
  EXPECT_FALSE(interpolation_from_name("quintic"));
}

TEST(IsoField, ProjectionLandsOnTheSurface) {
  const Volume v = sphere_volume(1.0, 0.1);
  for (Interpolation m : {Interpolation::trilinear, Interpolation::cubic, Interpolation::smooth_cubic}) {
    const IsoField f(v, 0.0, Inside::below, m);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    const double tol = 1e-6 * f.value_range();
    for (int i = 0; i < 200; ++i) {
      Vec3 dir(u(rng), u(rng), u(rng));
      if (dir.norm() < 0.1) continue;
      dir.normalize();
      Vec3 p = dir * (1.0 + 0.15 * u(rng));
      ASSERT_TRUE(f.project(p, 0.5, tol)) << interpolation_name(m) << " " << p.transpose();
      EXPECT_LE(std::abs(f.level(p)), tol);
      EXPECT_NEAR(p.norm(), 1.0, 0.02);  // the sampled sphere is the unit sphere to sampling accuracy
    }
  }
}

TEST(IsoField, ProjectionRespectsTheDistanceLimit) {
  const Volume v = sphere_volume(1.0, 0.1);
  const IsoField f(v, 0.0, Inside::below);
  Vec3 p(0.2, 0, 0);  // 0.8 from the surface
  const Vec3 start = p;
  EXPECT_FALSE(f.project(p, 0.3, 1e-9));
  EXPECT_LE((p - start).norm(), 0.3 + 1e-12);
}

TEST(IsoField, RootOnSegmentIsBracketedAndAccurate) {
  const Volume v = sphere_volume(1.0, 0.1);
  const IsoField f(v, 0.0, Inside::below);
  const Vec3 a(0, 0.2, 0), b(1.3, 0.2, 0);
  const Vec3 r = f.root_on_segment(a, b, 1e-10);
  EXPECT_LE(std::abs(f.level(r)), 1e-10);
  EXPECT_NEAR(r.y(), 0.2, 1e-15);
  EXPECT_GT(r.x(), 0.9);
  EXPECT_LT(r.x(), 1.0);
}
