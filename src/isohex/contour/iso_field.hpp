#pragma once
/// \file iso_field.hpp
/// \brief A volume, an isovalue and an inside convention seen as one level set: the
/// function every meshing stage evaluates, projects onto and measures distance to.

#include "isohex/volume/bspline.hpp"
#include "isohex/volume/interpolate.hpp"
#include "isohex/volume/volume.hpp"

#include <memory>
#include <optional>
#include <string_view>

namespace isohex {

/// How values between grid points are reconstructed.
enum class Interpolation : unsigned char {
  trilinear,        ///< the trilinear interpolant (C0; exact at grid points)
  cubic,            ///< interpolating cubic B-spline (C2; exact at grid points)
  smooth_cubic,     ///< smoothing cubic B-spline (C2; low-pass, for noisy scans)
};

std::string_view interpolation_name(Interpolation m);
std::optional<Interpolation> interpolation_from_name(std::string_view name);

/// The level set L(p) = ±(f(p) − isovalue), positive inside, zero on the isosurface.
///
/// Holds a reference to the volume, which must outlive it (and a B-spline copy of the
/// coefficients for the cubic modes).
class IsoField {
 public:
  IsoField(const Volume& volume, double isovalue, Inside inside = Inside::above,
           Interpolation interpolation = Interpolation::trilinear);

  /// L at world point p.
  [[nodiscard]] double level(const Vec3& p) const;
  /// L and its gradient at p.
  double level(const Vec3& p, Vec3& gradient) const;
  /// The interpolated volume value f(p) (not shifted by the isovalue).
  [[nodiscard]] double value(const Vec3& p) const;

  /// Moves `p` onto the isosurface: Newton steps along the gradient, then bisection once
  /// the zero is bracketed. Steps never exceed `max_distance` in all. Returns true when
  /// |L(p)| ≤ `tolerance` at the end; on failure `p` is the best point found.
  bool project(Vec3& p, double max_distance, double tolerance) const;

  /// The same within the plane x_axis = p[axis] (the rim where the isosurface meets a box
  /// face): Newton steps along the gradient's in-plane part, bisection once the zero is
  /// bracketed, steps within `max_distance` of the start. Returns true when |L(p)| ≤
  /// `tolerance` at the end.
  bool project_in_plane(Vec3& p, int axis, double max_distance, double tolerance) const;

  /// The root of L on the segment [a, b] when L(a), L(b) have opposite signs (bisection to
  /// `tolerance` in |L| or to a segment of 1e-12 of its length).
  [[nodiscard]] Vec3 root_on_segment(Vec3 a, Vec3 b, double tolerance) const;

  [[nodiscard]] const Volume& volume() const { return volume_; }
  [[nodiscard]] double isovalue() const { return isovalue_; }
  [[nodiscard]] Inside inside() const { return inside_; }
  [[nodiscard]] Interpolation interpolation() const { return interpolation_; }
  /// max − min of the volume's values (for relative tolerances).
  [[nodiscard]] double value_range() const { return range_; }

 private:
  const Volume& volume_;
  double isovalue_;
  Inside inside_;
  Interpolation interpolation_;
  double range_ = 0;
  std::shared_ptr<const CubicBSpline> spline_;
};

}  // namespace isohex
