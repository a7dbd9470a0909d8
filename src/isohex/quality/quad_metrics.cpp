// Quad scaled Jacobian, transcribed from Verdict 1.4.4+ (V_QuadMetric.cpp, V_TriMetric.cpp).
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/verdict_vector.hpp"

#include <cmath>

namespace isohex {

using detail::cross;
using detail::kDblMax;
using detail::VV;

namespace {

/// Verdict's tri_scaled_jacobian for the first three corners: a quad whose last two corners
/// coincide is treated as that triangle. Unsigned, scaled so that an equilateral triangle is 1.
double tri_scaled_jacobian(const std::array<Vec3, 4>& q) {
  VV e[3] = {VV::of(q[1]) - VV::of(q[0]), VV::of(q[2]) - VV::of(q[0]), VV::of(q[2]) - VV::of(q[1])};
  const double scale = detail::elem_scaling(q.data(), 3).scale;
  for (VV& v : e) v /= scale;
  const VV first = e[1] - e[0];
  const VV second = e[2] - e[0];
  double jac = cross(first, second).length();
  const double max_edge_length_product =
      std::fmax(e[0].length() * e[1].length(),
                std::fmax(e[1].length() * e[2].length(), e[0].length() * e[2].length()));
  if (max_edge_length_product < kVerdictDblMin) return 0.0;
  constexpr double kSqrt3 = 1.732050807568877293527446;
  constexpr double kTwoOverSqrt3 = 2.0 / kSqrt3;
  jac *= kTwoOverSqrt3;
  jac /= max_edge_length_product;
  return detail::clamp_dbl_max(jac);
}

}  // namespace

double quad_scaled_jacobian(const std::array<Vec3, 4>& q) {
  if (q[3] == q[2]) return tri_scaled_jacobian(q);

  const VV p[4] = {VV::of(q[0]), VV::of(q[1]), VV::of(q[2]), VV::of(q[3])};
  VV e[4] = {p[1] - p[0], p[2] - p[1], p[3] - p[2], p[0] - p[3]};

  // signed_corner_areas(): corner normals projected on the unit normal at the centre, on the
  // raw coordinates (as Verdict does), then divided by the squared diagonal.
  VV n = cross(e[0] - e[2], e[1] - e[3]);
  n.normalize();
  double area[4] = {detail::dot(n, cross(e[3], e[0])), detail::dot(n, cross(e[0], e[1])),
                    detail::dot(n, cross(e[1], e[2])), detail::dot(n, cross(e[2], e[3]))};

  const double scale = detail::elem_scaling(q.data(), 4).scale;
  double len[4];
  for (int i = 0; i < 4; ++i) {
    area[i] /= (scale * scale);
    e[i] /= scale;
    len[i] = e[i].length();
  }
  if (len[0] < kVerdictDblMin || len[1] < kVerdictDblMin || len[2] < kVerdictDblMin ||
      len[3] < kVerdictDblMin)
    return 0.0;

  double min_sj = kDblMax;
  min_sj = std::fmin(area[0] / (len[0] * len[3]), min_sj);
  min_sj = std::fmin(area[1] / (len[1] * len[0]), min_sj);
  min_sj = std::fmin(area[2] / (len[2] * len[1]), min_sj);
  min_sj = std::fmin(area[3] / (len[3] * len[2]), min_sj);
  return detail::clamp_dbl_max(min_sj);
}

}  // namespace isohex
