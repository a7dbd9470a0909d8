#pragma once
/// \file verdict_vector.hpp
/// \brief Internal: a 3-vector whose every operation rounds exactly as Verdict's VerdictVector.
///
/// Verdict evaluates `x*x + y*y + z*z` left to right, the cross product as
/// `(y1 z2 - z1 y2, z1 x2 - x1 z2, x1 y2 - y1 x2)`, and scales by division. Eigen is free to
/// reassociate its reductions, so the metrics use this type instead to reproduce Verdict's
/// results bit for bit (the library is compiled with -ffp-contract=off, so no FMA either).
/// Not part of the public API.

#include "isohex/quality/hex_quality.hpp"

#include <cmath>
#include <cstddef>

namespace isohex::detail {

using isohex::kVerdictDblMin;
/// Verdict's VERDICT_DBL_MAX, short.
inline constexpr double kDblMax = kVerdictDblMax;

/// Plain 3-vector with Verdict's operation order.
struct VV {
  double x = 0.0, y = 0.0, z = 0.0;

  static VV of(const Vec3& p) { return {p.x(), p.y(), p.z()}; }
  VV& operator+=(const VV& b) { x += b.x; y += b.y; z += b.z; return *this; }
  VV& operator-=(const VV& b) { x -= b.x; y -= b.y; z -= b.z; return *this; }
  VV& operator/=(double s) { x /= s; y /= s; z /= s; return *this; }
  [[nodiscard]] double length_squared() const { return x * x + y * y + z * z; }
  [[nodiscard]] double length() const { return std::sqrt(x * x + y * y + z * z); }
  /// VerdictVector::normalize(): divides by the length unless it is at most 2*DBL_MIN, in which
  /// case the vector becomes 0 and 0 is returned.
  double normalize() {
    const double mag = length();
    if (mag > kVerdictDblMin * 2.0) {
      x = x / mag; y = y / mag; z = z / mag;
      return mag;
    }
    x = y = z = 0.0;
    return 0.0;
  }
};

inline VV operator+(const VV& a, const VV& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline VV operator-(const VV& a, const VV& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline VV operator*(const VV& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
/// Cross product (Verdict's `operator*` on two vectors).
inline VV cross(const VV& a, const VV& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double dot(const VV& a, const VV& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
/// Verdict's triple product `Dot(a, b * c)`.
inline double triple(const VV& a, const VV& b, const VV& c) { return dot(a, cross(b, c)); }

/// Verdict's elem_scaling(): the centroid and bounding-box diagonal of `n` points, or (0, 1)
/// when the diagonal is below VERDICT_DBL_MIN.
struct ElemScale {
  VV center;
  double scale = 1.0;
};

inline ElemScale elem_scaling(const Vec3* p, std::size_t n) {
  VV lo{kDblMax, kDblMax, kDblMax}, hi{-kDblMax, -kDblMax, -kDblMax}, c{0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < n; ++i) {
    const double px = p[i].x(), py = p[i].y(), pz = p[i].z();
    if (px < lo.x) lo.x = px;
    if (py < lo.y) lo.y = py;
    if (px > hi.x) hi.x = px;
    if (py > hi.y) hi.y = py;
    if (pz < lo.z) lo.z = pz;
    if (pz > hi.z) hi.z = pz;
    c += VV{px, py, pz};
  }
  c /= static_cast<double>(n);
  double len = (hi - lo).length();
  if (len < kVerdictDblMin) {
    c = VV{0.0, 0.0, 0.0};
    len = 1.0;
  }
  return {c, len};
}

/// The `n` points translated to their centroid and divided by their bounding-box diagonal
/// (Verdict's apply_elem_scaling_on_points); returns the diagonal used.
inline double normalized_points(const Vec3* p, std::size_t n, VV* out) {
  const ElemScale s = elem_scaling(p, n);
  for (std::size_t i = 0; i < n; ++i) {
    out[i] = VV::of(p[i]);
    out[i] -= s.center;
    out[i] /= s.scale;
  }
  return s.scale;
}

/// Verdict's final clamp of a metric value into [-DBL_MAX, DBL_MAX].
inline double clamp_dbl_max(double v) {
  return v > 0 ? std::fmin(v, kDblMax) : std::fmax(v, -kDblMax);
}

}  // namespace isohex::detail
