#pragma once
/// \file bspline.hpp
/// \brief Cubic B-spline interpolation and smoothing of a volume: a C2 field for meshing
/// noisy data, with an exact gradient.
///
/// The field is f(x) = sum_k c_k beta3(t(x) - k) over the grid points k, with t the grid
/// coordinates of x and beta3 the centred cubic B-spline. In `interpolate` mode the
/// coefficients c come from the recursive prefilter of Unser, Aldroubi & Eden (IEEE TSP
/// 1993), so that f passes through every grid value; in `smooth` mode c are the grid
/// values themselves, which low-pass filters them (a grid value v becomes (v_{-1} + 4 v +
/// v_{+1}) / 6 along each axis) while still reproducing linear functions. Beyond the grid
/// the coefficients are mirrored about the first and last points (whole-sample
/// symmetry), the boundary condition the prefilter assumes; points outside the box are
/// clamped to it, as in sample().

#include "isohex/volume/volume.hpp"

#include <vector>

namespace isohex {

/// How CubicBSpline treats the grid values.
enum class BSplineMode : unsigned char {
  interpolate,  ///< pass through every grid value (prefiltered coefficients)
  smooth        ///< approximate: the grid values are the coefficients (smooths noise)
};

/// A cubic B-spline field over a volume. Holds one float coefficient per grid point.
class CubicBSpline {
 public:
  /// Computes the coefficients (for `interpolate`, a prefilter pass along each axis).
  explicit CubicBSpline(const Volume& volume, BSplineMode mode = BSplineMode::interpolate);

  /// The field at world point `p`.
  [[nodiscard]] double sample(const Vec3& p) const;
  /// The field and its gradient (world units) at `p`.
  double sample(const Vec3& p, Vec3& gradient) const;
  /// The gradient at `p` (0 along an axis where `p` is clamped onto the box).
  [[nodiscard]] Vec3 gradient(const Vec3& p) const;

  /// The coefficients as a volume with the source's geometry.
  [[nodiscard]] const Volume& coefficients() const { return coef_; }
  [[nodiscard]] BSplineMode mode() const { return mode_; }

 private:
  template <bool WithGradient>
  double evaluate(const Vec3& p, Vec3* gradient) const;

  Volume coef_;
  BSplineMode mode_;
};

/// The interpolating prefilter of one line of `n` samples, in place: afterwards
/// sum_k c_k beta3(i - k) equals the input sample i at every i, with the coefficients
/// mirrored beyond both ends. Exposed for tests.
void bspline_prefilter(double* line, std::size_t n);

}  // namespace isohex
