// Certified validity inside the element: Bernstein bounds of det J against dense sampling,
// the bow tie that Verdict's nine samples pass, the ratio and Gauss-point measures, and the
// volume balance of whole meshes.
#include "isohex/mesh/generate.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

using namespace isohex;

namespace {

using Corners = std::array<Vec3, 8>;

using isohex::test::unit_cube;

// Corners 3 and 7 thrown across the element (found by a random search): every corner frame
// and the centre frame are positive (scaled Jacobian 0.04), yet det J < 0 at Gauss points.
Corners bow_tie() {
  Corners p = unit_cube();
  p[3] = Vec3(0.31, 0.177, 0.416);
  p[7] = Vec3(0.945, 0.808, -0.639);
  return p;
}

// Dense sampling: min and max of det J on an n^3 lattice of the parameter cube.
std::pair<double, double> sampled(const Corners& p, int n) {
  double lo = INFINITY, hi = -INFINITY;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const double d = jacobian_determinant(p, i / (n - 1.0), j / (n - 1.0), k / (n - 1.0));
        lo = std::min(lo, d);
        hi = std::max(hi, d);
      }
  return {lo, hi};
}

// The quadratic Bernstein basis on [0, 1].
double b2(int i, double t) { return i == 0 ? (1 - t) * (1 - t) : i == 1 ? 2 * t * (1 - t) : t * t; }

Corners jittered(std::mt19937_64& rng, double amount) {
  std::normal_distribution<double> g(0, amount);
  Corners p = unit_cube();
  for (Vec3& x : p) x += Vec3(g(rng), g(rng), g(rng));
  return p;
}

}  // namespace

TEST(JacobianBounds, CoefficientsReproduceTheDeterminant) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> t(0, 1);
  for (int trial = 0; trial < 50; ++trial) {
    const Corners p = jittered(rng, 0.3);
    const Vec3 lo(0.25 * t(rng), 0.25 * t(rng), 0.25 * t(rng)), hi(0.5 + 0.5 * t(rng), 0.5 + 0.5 * t(rng), 1);
    const auto b = jacobian_bernstein(p, lo, hi);
    for (int s = 0; s < 20; ++s) {
      const double u = t(rng), v = t(rng), w = t(rng);
      double sum = 0;
      for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j)
          for (int i = 0; i < 3; ++i) sum += b[i + 3 * j + 9 * k] * b2(i, u) * b2(j, v) * b2(k, w);
      const double direct = jacobian_determinant(p, lo[0] + u * (hi[0] - lo[0]), lo[1] + v * (hi[1] - lo[1]),
                                                 lo[2] + w * (hi[2] - lo[2]));
      EXPECT_NEAR(sum, direct, 1e-12);
    }
  }
}

TEST(JacobianBounds, CornerCoefficientsAreTheCornerJacobians) {
  std::mt19937_64 rng(7);
  const Corners p = jittered(rng, 0.2);
  const auto b = jacobian_bernstein(p);
  for (int k = 0; k < 8; ++k) {
    const auto& nb = kCornerNeighbors[k];
    Eigen::Matrix3d A;
    for (int j = 0; j < 3; ++j) A.col(j) = p[nb[j]] - p[k];
    const int i = (k == 1 || k == 2 || k == 5 || k == 6) ? 2 : 0, j = (k == 2 || k == 3 || k == 6 || k == 7) ? 2 : 0,
              l = k >= 4 ? 2 : 0;
    EXPECT_NEAR(b[i + 3 * j + 9 * l], A.determinant(), 1e-13) << "corner " << k;
  }
}

TEST(JacobianBounds, ParallelepipedIsExact) {
  Corners p = unit_cube();
  Eigen::Matrix3d M;
  M << 2, 0.5, 0.1, 0, 1, 0.3, 0, 0, 3;
  for (Vec3& x : p) x = M * x + Vec3(100, -50, 7);
  const JacobianBounds b = jacobian_bounds(p);
  EXPECT_NEAR(b.min_lower, M.determinant(), 1e-9);
  EXPECT_NEAR(b.max_upper, M.determinant(), 1e-9);
  EXPECT_EQ(b.subdivisions, 0);
  EXPECT_NEAR(jacobian_ratio(p), 1.0, 1e-12);
  EXPECT_TRUE(certified_valid(p));
}

TEST(JacobianBounds, BoundsEncloseDenseSamplingOnRandomHexes) {
  std::mt19937_64 rng(11);
  int certified = 0, invalid = 0, undecided = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Corners p = jittered(rng, trial < 200 ? 0.15 : 0.35);
    const JacobianBounds b = jacobian_bounds(p);
    const auto [lo, hi] = sampled(p, 13);
    const double tol = 1e-12 * std::max(std::abs(lo), std::abs(hi));
    EXPECT_LE(b.min_lower, lo + tol);
    EXPECT_GE(b.max_upper, hi - tol);
    EXPECT_LE(b.min_lower, b.min_upper);
    EXPECT_LE(b.max_lower, b.max_upper);
    // The attained values are values of det J: no lower than the true minimum, which the
    // dense sampling overestimates by at most the refinement tolerance here.
    EXPECT_LE(b.min_upper, lo + 1e-3 * std::max(std::abs(lo), std::abs(hi)) + tol);
    if (b.valid()) {
      ++certified;
      EXPECT_GT(lo, 0) << "certified hex " << trial << " has a non-positive sample";
      EXPECT_TRUE(certified_valid(p, 0, 512));
    } else if (b.invalid()) {
      ++invalid;
      EXPECT_FALSE(certified_valid(p));
    } else {
      ++undecided;
    }
    EXPECT_EQ(b.valid(), jacobian_ratio(p) > 0);
    // The cheap test is sufficient: it never certifies what the full bounds do not.
    if (certified_valid(p)) EXPECT_TRUE(b.valid());
  }
  EXPECT_GT(certified, 100);
  EXPECT_GT(invalid, 20);
  EXPECT_EQ(undecided, 0);
}

TEST(JacobianBounds, BowTiePassesVerdictButIsNotValidInside) {
  const Corners p = bow_tie();
  EXPECT_GT(scaled_jacobian(p), 0);  // all nine of Verdict's samples are positive
  EXPECT_LT(gauss_min_jacobian(p), 0);
  const JacobianBounds b = jacobian_bounds(p);
  EXPECT_TRUE(b.invalid());
  EXPECT_FALSE(b.valid());
  EXPECT_FALSE(certified_valid(p, 0, 4096));
  EXPECT_LT(jacobian_ratio(p), 0);
  EXPECT_LT(sampled(p, 21).first, 0);
}

TEST(JacobianBounds, GaussPointsOfACube) {
  Corners p = unit_cube();
  for (Vec3& x : p) x *= 2;
  EXPECT_NEAR(gauss_min_jacobian(p), 8.0, 1e-12);
  EXPECT_NEAR(hex_metric(HexMetric::gauss_jacobian, p), 8.0, 1e-12);
  EXPECT_NEAR(hex_metric(HexMetric::jacobian_ratio, p), 1.0, 1e-12);
}

TEST(JacobianBounds, FlatAndCollapsedElements) {
  Corners flat = unit_cube();
  for (int k = 4; k < 8; ++k) flat[k][2] = 0;
  EXPECT_FALSE(jacobian_bounds(flat).valid());
  EXPECT_EQ(jacobian_ratio(flat), 0.0);
  EXPECT_FALSE(certified_valid(flat));
  Corners nan = unit_cube();
  nan[6][0] = std::nan("");
  EXPECT_FALSE(jacobian_bounds(nan).valid());
  EXPECT_FALSE(certified_valid(nan));
}

// The certificates take a non-finite corner anywhere (NaN, +inf, -inf in any coordinate of
// any corner, corner 0 included: every other corner is taken relative to it) as not valid,
// with a ratio bound of -1, whatever the floors: an infinite coefficient must never pass one.
TEST(JacobianBounds, NonFiniteCornersAreNeverCertified) {
  const double bad[] = {std::nan(""), std::numeric_limits<double>::infinity(),
                        -std::numeric_limits<double>::infinity()};
  for (int k = 0; k < 8; ++k)
    for (int c = 0; c < 3; ++c)
      for (double x : bad) {
        Corners p = unit_cube();
        p[k][c] = x;
        EXPECT_FALSE(certified_valid(p)) << k << " " << c << " " << x;
        EXPECT_FALSE(certified_valid(p, -1e300)) << k << " " << c << " " << x;
        EXPECT_FALSE(certified_valid_above_ratio(p, -1e300, -std::numeric_limits<double>::infinity()));
        double ratio = 0;
        EXPECT_FALSE(certified_valid_above_ratio(p, 0, -2, &ratio));
        EXPECT_EQ(ratio, -1.0) << k << " " << c << " " << x;
        EXPECT_EQ(jacobian_ratio_bound(p), -1.0) << k << " " << c << " " << x;
        const CertifiedQuality q = certified_quality(p);
        EXPECT_EQ(q.ratio_bound, -1.0);
        EXPECT_TRUE(!(q.scaled_jacobian > 0) || is_degenerate(q.scaled_jacobian)) << k << " " << c << " " << x;
        EXPECT_TRUE(!(certified_scaled_jacobian(p) > 0) || is_degenerate(certified_scaled_jacobian(p)));
      }
}

TEST(JacobianBounds, FloorIsRespected) {
  Corners p = unit_cube();
  EXPECT_TRUE(certified_valid(p, 0.99));
  EXPECT_FALSE(certified_valid(p, 1.0));
}

// The lattice computes each edge vector once for the 27 points (bernstein_box()); its corner
// coefficients are its values there, which must be jacobian_determinant()'s bit for bit (the
// optimisers' results must not move with how the lattice is computed). And the shape stage's
// one-evaluation test is the two tests it replaces, on valid, folded and flat hexes.
TEST(JacobianBounds, LatticeAndCombinedTestAgreeExactly) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> t(0, 1);
  std::size_t valid = 0, refused_by_ratio = 0, invalid = 0;
  for (int trial = 0; trial < 400; ++trial) {
    Corners p = jittered(rng, trial % 4 == 0 ? 0.45 : 0.2);
    for (Vec3& x : p) x = 1e3 * x + Vec3(-7e4, 3e3, 1e5);  // far from the origin, as scans are
    const Vec3 lo(0.5 * t(rng), 0.5 * t(rng), 0.5 * t(rng)), hi(0.5 + 0.5 * t(rng), 0.5 + 0.5 * t(rng), 1);
    const auto b = jacobian_bernstein(p, lo, hi);
    for (int c = 0; c < 8; ++c) {
      const double u = c & 1 ? hi[0] : lo[0], v = c & 2 ? hi[1] : lo[1], w = c & 4 ? hi[2] : lo[2];
      EXPECT_EQ(b[(c & 1 ? 2 : 0) + (c & 2 ? 6 : 0) + (c & 4 ? 18 : 0)], jacobian_determinant(p, u, v, w)) << trial;
    }
    const double ratio = jacobian_ratio_bound(p);
    for (double floor : {0.0, 1e6, 5e8})
      for (double ratio_floor : {-std::numeric_limits<double>::infinity(), 0.1, 0.4}) {
        const bool both = !(ratio < ratio_floor) && certified_valid(p, floor);
        EXPECT_EQ(certified_valid_above_ratio(p, floor, ratio_floor), both) << trial;
        valid += both;
        refused_by_ratio += ratio < ratio_floor && certified_valid(p, floor);
        invalid += !certified_valid(p, floor);
      }
  }
  EXPECT_GT(valid, 100u);  // every outcome is met
  EXPECT_GT(refused_by_ratio, 10u);
  EXPECT_GT(invalid, 10u);
}

// The coefficients come from a vectorised kernel (27 triple products side by side); they must
// be the very bits of det J sampled one point at a time (Eigen's cross and dot) on the lattice
// and converted: the whole element and sub-boxes, near and far from the origin.
TEST(JacobianBounds, CoefficientsAreThoseOfTheSampledLatticeBitForBit) {
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> t(0, 1);
  for (int trial = 0; trial < 300; ++trial) {
    Corners p = jittered(rng, trial % 3 == 0 ? 0.45 : 0.2);
    if (trial % 2) for (Vec3& x : p) x = 1e3 * x + Vec3(-7e4, 3e3, 1e5);
    const bool whole = trial % 4 < 2;
    const Vec3 lo = whole ? Vec3::Zero() : Vec3(0.5 * t(rng), 0.5 * t(rng), 0.5 * t(rng));
    const Vec3 hi = whole ? Vec3::Ones() : Vec3(0.5 + 0.5 * t(rng), 0.5 + 0.5 * t(rng), 1);
    std::array<double, 27> ref;
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) {
          const Vec3 m = 0.5 * (lo + hi);
          const double u = i == 0 ? lo[0] : i == 1 ? m[0] : hi[0];
          const double v = j == 0 ? lo[1] : j == 1 ? m[1] : hi[1];
          const double w = k == 0 ? lo[2] : k == 1 ? m[2] : hi[2];
          ref[i + 3 * j + 9 * k] = jacobian_determinant(p, u, v, w);
        }
    lattice_to_bernstein(ref);
    const std::array<double, 27> b = whole ? jacobian_bernstein(p) : jacobian_bernstein(p, lo, hi);
    for (int n = 0; n < 27; ++n) EXPECT_EQ(b[n], ref[n]) << trial << " coefficient " << n;
  }
}

TEST(VolumeBalance, BoxMatchesAndAFoldIsSeen) {
  HexMesh box = box_mesh(4, 3, 2, Vec3::Zero(), Vec3(2, 3, 1));
  VolumeBalance v = volume_balance(box);
  EXPECT_NEAR(v.enclosed, 6.0, 1e-12);
  EXPECT_NEAR(v.hexes, 6.0, 1e-12);
  EXPECT_NEAR(v.signed_hexes, 6.0, 1e-12);
  // Push an interior vertex across its neighbours: signed volumes still add up to the
  // enclosed volume, |det J| does not.
  HexMesh folded = box_mesh(4, 4, 4);
  const MeshJacobians before = mesh_jacobians(folded);
  EXPECT_TRUE(std::all_of(before.valid.begin(), before.valid.end(), [](auto x) { return x == 1; }));
  Index centre = -1;
  for (Index i = 0; i < folded.num_vertices(); ++i)
    if ((folded.points[i] - Vec3(0.5, 0.5, 0.5)).norm() < 1e-12) centre = i;
  ASSERT_GE(centre, 0);
  folded.points[centre] += Vec3(0.4, 0.05, 0.02);
  v = volume_balance(folded);
  EXPECT_NEAR(v.signed_hexes, 1.0, 1e-12);
  EXPECT_NEAR(v.enclosed, 1.0, 1e-12);
  EXPECT_GT(v.excess(), 1e-3);
  const MeshJacobians after = mesh_jacobians(folded);
  EXPECT_GT(std::count(after.valid.begin(), after.valid.end(), 0), 0);
}
