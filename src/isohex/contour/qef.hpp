#pragma once
/// \file qef.hpp
/// \brief The quadric error function of dual contouring: the point closest, in the
/// least-squares sense, to the tangent planes of a cell's Hermite data.

#include "isohex/mesh/hex_mesh.hpp"

namespace isohex::contour {

/// Accumulates planes n·(x − p) = 0 and minimises Σ (n·(x − p))² (Ju et al. 2002).
///
/// The minimiser is taken relative to the mass point m of the plane points: x = m + A⁺ b
/// with A = Σ n nᵀ, b = Σ n nᵀ (p − m), and A⁺ the SVD pseudo-inverse with singular values
/// below `relative_cutoff` × the largest dropped. Along a flat or ridge-shaped surface the
/// dropped directions leave x at the mass point instead of running off along the surface.
class Qef {
 public:
  /// Adds the tangent plane through `point` with normal `normal` (any non-zero length).
  void add(const Vec3& point, const Vec3& normal);
  /// The minimiser; the mass point when no normal was usable. Requires count() > 0.
  [[nodiscard]] Vec3 solve(double relative_cutoff = 0.1) const;
  /// The mass point of the added points.
  [[nodiscard]] Vec3 mass_point() const { return sum_ / static_cast<double>(count_); }
  [[nodiscard]] int count() const { return count_; }

 private:
  static constexpr int kMax = 12;  // a cell has 12 edges
  Vec3 points_[kMax];
  Vec3 normals_[kMax];
  int count_ = 0, planes_ = 0;
  Vec3 sum_{0, 0, 0};
};

}  // namespace isohex::contour
