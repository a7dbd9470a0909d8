// Trilinear and cubic B-spline fields over a volume, the inside convention, and the value
// statistics with Otsu's isovalue.
#include "isohex/volume/bspline.hpp"
#include "isohex/volume/interpolate.hpp"
#include "isohex/volume/statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using namespace isohex;

namespace {

/// A volume sampling `f` at its grid points.
template <class F>
Volume make_volume(std::array<Index, 3> dims, const Vec3& spacing, const Vec3& origin, F f) {
  Volume v;
  v.dims = dims;
  v.spacing = spacing;
  v.origin = origin;
  v.values.resize(v.size());
  for (Index k = 0; k < dims[2]; ++k)
    for (Index j = 0; j < dims[1]; ++j)
      for (Index i = 0; i < dims[0]; ++i) v.at(i, j, k) = static_cast<float>(f(v.point(i, j, k)));
  return v;
}

/// A random point of the box [lo, hi].
Vec3 random_point(std::mt19937& rng, const Vec3& lo, const Vec3& hi) {
  std::uniform_real_distribution<double> u(0, 1);
  return lo + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(hi - lo);
}

}  // namespace

TEST(VolumeTrilinear, ReproducesLinearFieldsAndTheirGradient) {
  // Dyadic spacing and coefficients: every grid value is exact in float.
  const Vec3 spacing(0.5, 2, 1.25), origin(-1, 3, 0.5);
  const auto f = [](const Vec3& p) { return 2 + 0.5 * p.x() - 0.25 * p.y() + 2 * p.z(); };
  const Volume v = make_volume({7, 5, 6}, spacing, origin, f);
  std::mt19937 rng(3);
  for (int n = 0; n < 2000; ++n) {
    const Vec3 p = random_point(rng, v.origin, v.max_corner());
    Vec3 g;
    EXPECT_NEAR(sample(v, p, g), f(p), 1e-12) << p.transpose();
    EXPECT_NEAR((g - Vec3(0.5, -0.25, 2)).norm(), 0, 1e-12) << p.transpose();
  }
  // At grid points the interpolant is the grid value itself.
  for (Index k = 0; k < 6; ++k)
    for (Index i = 0; i < 7; ++i) EXPECT_EQ(sample(v, v.point(i, 2, k)), v.at(i, 2, k));
}

TEST(VolumeTrilinear, CellInterpolationAndClamping) {
  Volume v;
  v.dims = {2, 2, 2};
  v.values = {0, 1, 2, 3, 4, 5, 6, 7};  // f = x + 2y + 4z on the unit cube
  EXPECT_DOUBLE_EQ(sample(v, Vec3(0.5, 0.5, 0.5)), 3.5);
  EXPECT_DOUBLE_EQ(sample(v, Vec3(0.25, 0.75, 0.125)), 0.25 + 1.5 + 0.5);
  // Outside the box the nearest boundary value is taken, and the clamped axes have no slope.
  Vec3 g;
  EXPECT_DOUBLE_EQ(sample(v, Vec3(-3, 0.5, 9), g), 0 + 1 + 4);
  EXPECT_EQ(g, Vec3(0, 2, 0));
  // A bilinear (not linear) cell: f = x·y is reproduced, with gradient (y, x).
  v.values = {0, 0, 0, 1, 0, 0, 0, 1};
  EXPECT_DOUBLE_EQ(sample(v, Vec3(0.3, 0.6, 0.2), g), 0.3 * 0.6);
  EXPECT_NEAR((g - Vec3(0.6, 0.3, 0)).norm(), 0, 1e-15);
  // An axis with a single grid point is constant along it.
  Volume flat;
  flat.dims = {3, 1, 1};
  flat.values = {1, 3, 7};
  EXPECT_DOUBLE_EQ(sample(flat, Vec3(1.5, 42, -1), g), 5);
  EXPECT_EQ(g, Vec3(4, 0, 0));
}

TEST(VolumeInside, Convention) {
  EXPECT_EQ(Inside{}, Inside::above);
  EXPECT_TRUE(is_inside(1200, 1150, Inside::above));
  EXPECT_FALSE(is_inside(1100, 1150, Inside::above));
  EXPECT_TRUE(is_inside(-0.5, 0, Inside::below));
  EXPECT_FALSE(is_inside(0, 0, Inside::below));  // on the surface
  EXPECT_FALSE(is_inside(0, 0, Inside::above));
  EXPECT_EQ(inside_level(3, 1, Inside::above), 2);
  EXPECT_EQ(inside_level(3, 1, Inside::below), -2);
  EXPECT_EQ(inside_from_name("below"), Inside::below);
  EXPECT_EQ(inside_name(Inside::above), "above");
  EXPECT_FALSE(inside_from_name("inside").has_value());
}

TEST(VolumeBSpline, PrefilterMakesTheSplineInterpolate) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-10, 10);
  for (std::size_t n : {2u, 3u, 7u, 40u}) {
    std::vector<double> s(n), c;
    for (double& x : s) x = u(rng);
    c = s;
    bspline_prefilter(c.data(), n);
    // sum_k c_k beta3(i - k) with mirrored coefficients: (c_{i-1} + 4 c_i + c_{i+1}) / 6.
    const auto at = [&](std::int64_t k) {
      const auto period = static_cast<std::int64_t>(2 * n - 2);
      k = ((k % period) + period) % period;
      return c[static_cast<std::size_t>(k < static_cast<std::int64_t>(n) ? k : period - k)];
    };
    for (std::size_t i = 0; i < n; ++i) {
      const auto k = static_cast<std::int64_t>(i);
      EXPECT_NEAR((at(k - 1) + 4 * at(k) + at(k + 1)) / 6, s[i], 1e-12) << "n=" << n << " i=" << i;
    }
  }
}

TEST(VolumeBSpline, InterpolatesGridValuesAndCubicsInTheInterior) {
  const Vec3 spacing(0.5, 0.25, 1), origin(1, -2, 0);
  const auto cubic = [](const Vec3& p) { return 0.01 * p.x() * p.x() * p.x() - p.x() * p.y() + 3 * p.z() * p.z() + 1; };
  const Volume v = make_volume({40, 36, 30}, spacing, origin, cubic);
  const CubicBSpline spline(v);
  for (Index i = 0; i < 40; i += 3) EXPECT_NEAR(spline.sample(v.point(i, 0, 29)), v.at(i, 0, 29), 2e-4);
  // Away from the mirrored boundaries (which bend a cubic) the spline reproduces it.
  std::mt19937 rng(9);
  const Vec3 lo = v.point(12, 12, 12), hi = v.point(27, 23, 17);
  for (int n = 0; n < 300; ++n) {
    const Vec3 p = random_point(rng, lo, hi);
    Vec3 g;
    const double value = spline.sample(p, g);
    EXPECT_NEAR(value, cubic(p), 1e-4 * (1 + std::abs(cubic(p))));
    const Vec3 exact(0.03 * p.x() * p.x() - p.y(), -p.x(), 6 * p.z());
    EXPECT_NEAR((g - exact).norm(), 0, 1e-3 * (1 + exact.norm())) << p.transpose();
    EXPECT_EQ(spline.gradient(p), g);
    EXPECT_EQ(spline.sample(p), value);
  }
}

TEST(VolumeBSpline, GradientMatchesFiniteDifferences) {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0, 1);
  const Volume v = make_volume({12, 9, 10}, Vec3(1, 0.5, 2), Vec3(0, 0, 0), [&](const Vec3&) { return noise(rng); });
  for (BSplineMode mode : {BSplineMode::interpolate, BSplineMode::smooth}) {
    const CubicBSpline s(v, mode);
    for (int n = 0; n < 100; ++n) {
      const Vec3 p = random_point(rng, v.origin, v.max_corner());
      const Vec3 g = s.gradient(p);
      for (int a = 0; a < 3; ++a) {
        const double h = 1e-5;
        Vec3 e = Vec3::Zero();
        e[a] = h;
        if (p[a] - h < 0 || p[a] + h > v.max_corner()[a]) continue;
        EXPECT_NEAR(g[a], (s.sample(p + e) - s.sample(p - e)) / (2 * h), 1e-5 * (1 + std::abs(g[a])));
      }
    }
  }
}

TEST(VolumeBSpline, SmoothingReproducesLinearFieldsAndDampsNoise) {
  const auto linear = [](const Vec3& p) { return 3 - p.x() + 0.5 * p.y() + 2 * p.z(); };
  const Volume lin = make_volume({10, 10, 10}, Vec3(1, 1, 1), Vec3(0, 0, 0), linear);
  const CubicBSpline smooth(lin, BSplineMode::smooth);
  EXPECT_EQ(smooth.mode(), BSplineMode::smooth);
  std::mt19937 rng(13);
  for (int n = 0; n < 200; ++n) {
    const Vec3 p = random_point(rng, Vec3(1, 1, 1), Vec3(8, 8, 8));  // one cell in from the mirror
    EXPECT_NEAR(smooth.sample(p), linear(p), 1e-5);
  }
  // White noise: smoothing divides the variance at grid points by about 8 (3 axes of
  // the kernel (1 4 1)/6, whose squared weights sum to 1/2), interpolation keeps it.
  std::normal_distribution<double> noise(0, 1);
  const Volume v = make_volume({30, 30, 30}, Vec3(1, 1, 1), Vec3(0, 0, 0), [&](const Vec3&) { return noise(rng); });
  const CubicBSpline s(v, BSplineMode::smooth), interp(v);
  double raw = 0, smoothed = 0, interpolated = 0;
  for (Index k = 1; k < 29; ++k)
    for (Index j = 1; j < 29; ++j)
      for (Index i = 1; i < 29; ++i) {
        raw += v.at(i, j, k) * v.at(i, j, k);
        smoothed += std::pow(s.sample(v.point(i, j, k)), 2);
        interpolated += std::pow(interp.sample(v.point(i, j, k)), 2);
      }
  EXPECT_NEAR(smoothed / raw, 0.125, 0.02);
  EXPECT_NEAR(interpolated / raw, 1.0, 1e-6);
}

TEST(VolumeStatistics, RangeMeanHistogramIgnoringNonFinite) {
  Volume v;
  v.dims = {3, 2, 1};
  v.values = {1, 2, 3, 4, std::numeric_limits<float>::quiet_NaN(), 10};
  const ValueStatistics s = value_statistics(v);
  EXPECT_EQ(s.count, 5u);
  EXPECT_EQ(s.non_finite, 1u);
  EXPECT_EQ(s.min, 1);
  EXPECT_EQ(s.max, 10);
  EXPECT_DOUBLE_EQ(s.mean, 4);
  const ValueHistogram h = value_histogram(v, s, 3);  // bins of width 3 from 1
  EXPECT_EQ(h.counts, (std::vector<std::size_t>{3, 1, 1}));
  EXPECT_EQ(h.edge(0), 1);
  EXPECT_EQ(h.edge(3), 10);
  Volume constant;
  constant.dims = {2, 1, 1};
  constant.values = {5, 5};
  const ValueHistogram c = value_histogram(constant, value_statistics(constant), 16);
  EXPECT_EQ(c.counts, (std::vector<std::size_t>{2}));
  EXPECT_EQ(otsu_threshold(c), 5);
}

TEST(VolumeStatistics, OtsuSplitsTwoLevelsInTheMiddle) {
  // A ball of 50 in a background of 10.
  const Volume v = make_volume({20, 20, 20}, Vec3(1, 1, 1), Vec3(0, 0, 0),
                               [](const Vec3& p) { return (p - Vec3(9.5, 9.5, 9.5)).norm() < 6 ? 50.0 : 10.0; });
  EXPECT_DOUBLE_EQ(otsu_isovalue(v), 30);
  // Two noisy classes: the threshold falls between them, nearer the valley than either mode.
  std::mt19937 rng(17);
  std::normal_distribution<double> dark(100, 15), bright(900, 60);
  std::bernoulli_distribution which(0.3);
  const Volume mix = make_volume({30, 30, 30}, Vec3(1, 1, 1), Vec3(0, 0, 0),
                                 [&](const Vec3&) { return which(rng) ? bright(rng) : dark(rng); });
  const double t = otsu_isovalue(mix);
  EXPECT_GT(t, 250);
  EXPECT_LT(t, 750);
}
