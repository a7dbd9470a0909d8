#include "isohex/contour/qef.hpp"

#include <Eigen/SVD>

namespace isohex::contour {

void Qef::add(const Vec3& point, const Vec3& normal) {
  sum_ += point;
  ++count_;
  const double n = normal.norm();
  if (planes_ >= kMax || !(n > 0) || !std::isfinite(n)) return;
  points_[planes_] = point;
  normals_[planes_] = normal / n;
  ++planes_;
}

Vec3 Qef::solve(double relative_cutoff) const {
  const Vec3 m = mass_point();
  if (planes_ == 0) return m;
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Vec3 b = Vec3::Zero();
  for (int i = 0; i < planes_; ++i) {
    const Vec3& n = normals_[i];
    a += n * n.transpose();
    b += n * n.dot(points_[i] - m);
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 s = svd.singularValues();
  Vec3 inv = Vec3::Zero();
  for (int i = 0; i < 3; ++i)
    if (s[i] > relative_cutoff * s[0]) inv[i] = 1 / s[i];
  return m + svd.matrixV() * inv.asDiagonal() * svd.matrixU().transpose() * b;
}

}  // namespace isohex::contour
