// LevelSet::bracket(): where a scan's values sit on a plateau just off the isovalue, Newton's
// steps (project()) have no gradient to follow; bracketing finds the surface close by.
#include "isohex/contour/iso_field.hpp"
#include "isohex/contour/region.hpp"

#include <gtest/gtest.h>

#include <memory>

namespace isohex::contour {
namespace {

// 12 x 4 x 4 unit samples: 0.49 for x <= 6 (a plateau just below the isovalue 0.5), 1 beyond;
// the isosurface is the plane x = 6 + 0.01 / 0.51. (The field refers to the volume: static.)
LevelSet plateau() {
  static const Volume v = [] {
    Volume u;
    u.dims = {12, 4, 4};
    u.values.assign(u.size(), 0.49f);
    for (Index k = 0; k < 4; ++k)
      for (Index j = 0; j < 4; ++j)
        for (Index i = 7; i < 12; ++i) u.at(i, j, k) = 1.0f;
    return u;
  }();
  return LevelSet(std::make_shared<const IsoField>(v, 0.5, Inside::above));
}

TEST(ContourLevelSet, BracketFindsTheSurfaceAcrossAPlateau) {
  const LevelSet s = plateau();
  const double at = 6 + 0.01 / 0.51;
  const Vec3 start(3.3, 1.5, 1.5);
  Vec3 p = start;
  EXPECT_FALSE(s.project(p, 4.0));  // no gradient on the plateau
  p = start;
  ASSERT_TRUE(s.bracket(p, 4.0));
  EXPECT_LE(std::abs(s.level(p)), s.tolerance());
  EXPECT_NEAR(p.x(), at, 1e-6);
  EXPECT_NEAR((p - start).norm(), at - start.x(), 1e-6);  // along the axis, not farther
  // Beyond the reach: refused, and p stays where it was.
  p = start;
  EXPECT_FALSE(s.bracket(p, 2.0));
  EXPECT_EQ(p, start);
  // From the other side, the nearest sign change (not one farther along another direction).
  Vec3 q(8.5, 1.2, 1.7);
  ASSERT_TRUE(s.bracket(q, 4.0));
  EXPECT_NEAR(q.x(), at, 1e-6);
  EXPECT_NEAR(q.y(), 1.2, 1e-12);
  EXPECT_NEAR(q.z(), 1.7, 1e-12);
}

}  // namespace
}  // namespace isohex::contour
