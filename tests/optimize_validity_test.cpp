// Property test of issue 15: random optimisation runs never take a hex that is valid inside
// out of that set, and a run that reports nothing inverted leaves every hex certified. The
// oracle is jacobian_bounds() (adaptive Bernstein bounds to 1e-3), not the optimisers' own
// cheap test, and dense sampling of det J on the hexes the optimisers moved.
#include "isohex/mesh/generate.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/quality/jacobian_bounds.hpp"

#include <gtest/gtest.h>

#include <algorithm>

using namespace isohex;

namespace {

bool sampled_positive(const std::array<Vec3, 8>& p, int n = 9) {
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        if (!(jacobian_determinant(p, i / (n - 1.0), j / (n - 1.0), k / (n - 1.0)) > 0)) return false;
  return true;
}

}  // namespace

TEST(OptimizeValidity, RandomRunsKeepEveryCertifiedHexCertified) {
  std::size_t runs = 0, certified_before = 0, not_certified_before = 0;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    HexMesh m = box_mesh(5, 5, 5);
    jitter(m, seed <= 4 ? 0.06 : 0.09, seed);  // × the cell size 0.2: some hexes fold inside
    const MeshJacobians before = mesh_jacobians(m);
    certified_before += static_cast<std::size_t>(std::count(before.valid.begin(), before.valid.end(), 1));
    not_certified_before += static_cast<std::size_t>(std::count(before.valid.begin(), before.valid.end(), 0));
    OptimizeOptions o;
    o.untangle = seed % 2 == 0;  // shape + worst alone, or with the untangler first
    const OptimizeResult r = optimize_mesh(m, fixed_mask(m, FixedVertices::boundary), o);
    const MeshJacobians after = mesh_jacobians(m);
    for (Index h = 0; h < m.num_hexes(); ++h) {
      if (before.valid[h]) EXPECT_TRUE(after.valid[h]) << "seed " << seed << " hex " << h;
      if (after.valid[h]) EXPECT_TRUE(sampled_positive(m.corners(h))) << "seed " << seed << " hex " << h;
    }
    if (r.untangled && r.untangle.inverted == 0)
      EXPECT_EQ(std::count(after.valid.begin(), after.valid.end(), 0), 0) << "seed " << seed;
    ++runs;
  }
  EXPECT_EQ(runs, 8u);
  EXPECT_GT(certified_before, 500u);
  EXPECT_GT(not_certified_before, 0u);  // the runs start with folds to repair
}

// The bow tie of quality_jacobian_test: its nine samples are positive, so an optimiser that
// counted them would leave it; the untangler must see the fold and repair it.
TEST(OptimizeValidity, UntanglerRepairsAFoldBetweenVerdictsSamples) {
  HexMesh m = box_mesh(3, 3, 3);
  // The centre hex (all its vertices free) made the bow tie: corners 3 and 7 thrown across it.
  Index centre_hex = -1;
  for (Index h = 0; h < m.num_hexes(); ++h) {
    Vec3 c = Vec3::Zero();
    for (const Vec3& x : m.corners(h)) c += x / 8;
    if ((c - Vec3(0.5, 0.5, 0.5)).norm() < 1e-9) centre_hex = h;
  }
  ASSERT_GE(centre_hex, 0);
  const Vec3 lo = m.points[m.hexes[centre_hex][0]];
  const double cell = 1.0 / 3;
  m.points[m.hexes[centre_hex][3]] = lo + cell * Vec3(0.31, 0.177, 0.416);
  m.points[m.hexes[centre_hex][7]] = lo + cell * Vec3(0.945, 0.808, -0.639);
  const auto p = m.corners(centre_hex);
  ASSERT_FALSE(jacobian_bounds(p).valid());
  ASSERT_GT(jacobian_bounds(p).max_upper, 0);
  OptimizeOptions o;
  const OptimizeResult r = optimize_mesh(m, fixed_mask(m, FixedVertices::boundary), o);
  EXPECT_EQ(r.untangle.inverted, 0u);
  const MeshJacobians after = mesh_jacobians(m);
  EXPECT_EQ(std::count(after.valid.begin(), after.valid.end(), 0), 0);
}

// A pillow hex of cthead's bone at h 5 (iso 1200) that the untangler once left folded on a
// side face (min det J -10 against a max of 402; all 8 corners positive): its boundary quad
// fixed, its inner face free. The untangler must find a place that certifies it.
TEST(OptimizeValidity, UntanglerCertifiesAPillowHexFoldedOnASideFace) {
  HexMesh m;
  m.points = {{74.356398, 71.630073, 172.717386}, {77.212710, 72.524009, 171.702752},
              {67.293245, 85.950662, 175.474016}, {71.896603, 72.388942, 177.815059},
              {72.687742, 71.548922, 174.528996}, {78.345319, 74.062944, 172.216483},
              {74.328825, 78.343600, 177.254988}, {72.915504, 74.354524, 177.274097}};
  m.hexes = {{0, 1, 2, 3, 4, 5, 6, 7}};
  ASSERT_FALSE(jacobian_bounds(m.corners(0)).valid());
  const std::vector<std::uint8_t> fixed = {1, 1, 1, 1, 0, 0, 0, 0};
  const UntangleResult r = untangle(m, fixed, UntangleOptions{});
  EXPECT_EQ(r.inverted, 0u);
  const JacobianBounds b = jacobian_bounds(m.corners(0));
  EXPECT_TRUE(b.valid()) << b.min_lower;
  EXPECT_TRUE(sampled_positive(m.corners(0), 17));
}
