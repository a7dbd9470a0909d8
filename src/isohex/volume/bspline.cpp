#include "isohex/volume/bspline.hpp"

#include "isohex/volume/interpolate.hpp"

#include <tbb/parallel_for.h>

#include <array>
#include <cmath>

namespace isohex {

namespace {

/// The pole of the cubic B-spline's inverse filter, sqrt(3) - 2.
const double kPole = std::sqrt(3.0) - 2.0;

/// Index k folded into [0, n) by whole-sample mirroring about 0 and n-1.
Index mirror(std::int64_t k, Index n) {
  if (n == 1) return 0;
  const std::int64_t period = 2 * static_cast<std::int64_t>(n) - 2;
  k %= period;
  if (k < 0) k += period;
  return static_cast<Index>(k < n ? k : period - k);
}

/// The 4 taps (first index t0 - 1) and their weights and derivative weights at grid
/// coordinate t along an axis of n points; `clamped` when t lies off the axis.
struct Taps {
  std::array<Index, 4> index{};
  std::array<double, 4> w{}, dw{};
  bool clamped = false;
};

Taps taps(double t, Index n) {
  Taps out;
  const double last = static_cast<double>(n - 1);
  if (!(t >= 0)) out.clamped = true, t = 0;  // also NaN
  if (t > last) out.clamped = true, t = last;
  const double fl = std::floor(t);
  const double f = t - fl, g = 1 - f;
  const auto i = static_cast<std::int64_t>(fl);
  for (int k = 0; k < 4; ++k) out.index[k] = mirror(i - 1 + k, n);
  out.w = {g * g * g / 6, (3 * f * f * f - 6 * f * f + 4) / 6, (-3 * f * f * f + 3 * f * f + 3 * f + 1) / 6,
           f * f * f / 6};
  out.dw = {-g * g / 2, 1.5 * f * f - 2 * f, -1.5 * f * f + f + 0.5, f * f / 2};
  if (out.clamped) out.dw = {0, 0, 0, 0};
  return out;
}

/// Prefilters every line of `v` along `axis`.
void prefilter_axis(Volume& v, int axis) {
  const Index n = v.dims[axis];
  if (n < 2) return;
  const std::array<std::size_t, 3> stride = {1, static_cast<std::size_t>(v.dims[0]),
                                             static_cast<std::size_t>(v.dims[0]) * static_cast<std::size_t>(v.dims[1])};
  const int a1 = axis == 0 ? 1 : 0, a2 = axis == 2 ? 1 : 2;  // the two other axes
  tbb::parallel_for(Index{0}, v.dims[a2], [&](Index q) {
    std::vector<double> line(static_cast<std::size_t>(n));
    for (Index p = 0; p < v.dims[a1]; ++p) {
      const std::size_t base = static_cast<std::size_t>(p) * stride[a1] + static_cast<std::size_t>(q) * stride[a2];
      for (Index i = 0; i < n; ++i) line[i] = v.values[base + static_cast<std::size_t>(i) * stride[axis]];
      bspline_prefilter(line.data(), line.size());
      for (Index i = 0; i < n; ++i)
        v.values[base + static_cast<std::size_t>(i) * stride[axis]] = static_cast<float>(line[i]);
    }
  });
}

}  // namespace

void bspline_prefilter(double* c, std::size_t n) {
  if (n < 2) return;
  const double z = kPole;
  const double gain = (1 - z) * (1 - 1 / z);  // 6 for the cubic B-spline
  for (std::size_t k = 0; k < n; ++k) c[k] *= gain;
  // Causal initial value for the mirrored signal of period 2n-2, summed exactly.
  const std::size_t period = 2 * n - 2;
  double sum = 0, zk = 1;
  for (std::size_t k = 0; k < period; ++k, zk *= z) sum += zk * c[k < n ? k : period - k];
  c[0] = sum / (1 - zk);
  for (std::size_t k = 1; k < n; ++k) c[k] += z * c[k - 1];
  // Anticausal pass, started from the mirror condition at the last sample.
  c[n - 1] = (z / (z * z - 1)) * (c[n - 1] + z * c[n - 2]);
  for (std::size_t k = n - 1; k-- > 0;) c[k] = z * (c[k + 1] - c[k]);
}

CubicBSpline::CubicBSpline(const Volume& volume, BSplineMode mode) : coef_(volume), mode_(mode) {
  if (mode == BSplineMode::interpolate)
    for (int axis = 0; axis < 3; ++axis) prefilter_axis(coef_, axis);
}

template <bool WithGradient>
double CubicBSpline::evaluate(const Vec3& p, Vec3* gradient) const {
  const Vec3 t = grid_coordinates(coef_, p);
  const Taps tx = taps(t.x(), coef_.dims[0]), ty = taps(t.y(), coef_.dims[1]), tz = taps(t.z(), coef_.dims[2]);
  double value = 0, gx = 0, gy = 0, gz = 0;
  for (int c = 0; c < 4; ++c) {
    double v_z = 0, gx_z = 0, gy_z = 0;
    for (int b = 0; b < 4; ++b) {
      double v_y = 0, gx_y = 0;
      for (int a = 0; a < 4; ++a) {
        const double coef = coef_.at(tx.index[a], ty.index[b], tz.index[c]);
        v_y += tx.w[a] * coef;
        if constexpr (WithGradient) gx_y += tx.dw[a] * coef;
      }
      v_z += ty.w[b] * v_y;
      if constexpr (WithGradient) {
        gx_z += ty.w[b] * gx_y;
        gy_z += ty.dw[b] * v_y;
      }
    }
    value += tz.w[c] * v_z;
    if constexpr (WithGradient) {
      gx += tz.w[c] * gx_z;
      gy += tz.w[c] * gy_z;
      gz += tz.dw[c] * v_z;
    }
  }
  if constexpr (WithGradient) *gradient = Vec3(gx, gy, gz).cwiseQuotient(coef_.spacing);
  return value;
}

double CubicBSpline::sample(const Vec3& p) const { return evaluate<false>(p, nullptr); }

double CubicBSpline::sample(const Vec3& p, Vec3& gradient) const { return evaluate<true>(p, &gradient); }

Vec3 CubicBSpline::gradient(const Vec3& p) const {
  Vec3 g;
  evaluate<true>(p, &g);
  return g;
}

}  // namespace isohex
