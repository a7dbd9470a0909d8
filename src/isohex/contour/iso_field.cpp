#include "isohex/contour/iso_field.hpp"

#include <algorithm>
#include <cmath>

namespace isohex {

std::string_view interpolation_name(Interpolation m) {
  switch (m) {
    case Interpolation::trilinear: return "trilinear";
    case Interpolation::cubic: return "cubic";
    case Interpolation::smooth_cubic: return "smooth-cubic";
  }
  return "trilinear";
}

std::optional<Interpolation> interpolation_from_name(std::string_view name) {
  for (Interpolation m : {Interpolation::trilinear, Interpolation::cubic, Interpolation::smooth_cubic})
    if (interpolation_name(m) == name) return m;
  return std::nullopt;
}

IsoField::IsoField(const Volume& volume, double isovalue, Inside inside, Interpolation interpolation)
    : volume_(volume), isovalue_(isovalue), inside_(inside), interpolation_(interpolation) {
  if (!volume.values.empty()) {
    auto [lo, hi] = std::minmax_element(volume.values.begin(), volume.values.end());
    range_ = static_cast<double>(*hi) - static_cast<double>(*lo);
  }
  if (interpolation != Interpolation::trilinear)
    spline_ = std::make_shared<CubicBSpline>(
        volume, interpolation == Interpolation::cubic ? BSplineMode::interpolate : BSplineMode::smooth);
}

double IsoField::value(const Vec3& p) const { return spline_ ? spline_->sample(p) : sample(volume_, p); }

double IsoField::level(const Vec3& p) const { return inside_level(value(p), isovalue_, inside_); }

double IsoField::level(const Vec3& p, Vec3& g) const {
  const double v = spline_ ? spline_->sample(p, g) : sample(volume_, p, g);
  if (inside_ == Inside::below) g = -g;
  return inside_level(v, isovalue_, inside_);
}

Vec3 IsoField::root_on_segment(Vec3 a, Vec3 b, double tolerance) const {
  double la = level(a), lb = level(b);
  if (la == 0) return a;
  if (lb == 0) return b;
  const double min_len = 1e-12 * (b - a).norm();
  for (int it = 0; it < 200; ++it) {
    // Regula falsi guarded by bisection: fast on smooth fields, never stuck.
    const double t = std::clamp(la / (la - lb), 0.05, 0.95);
    const Vec3 m = it % 3 == 2 ? Vec3(0.5 * (a + b)) : Vec3(a + t * (b - a));
    const double lm = level(m);
    if (std::abs(lm) <= tolerance || (b - a).norm() <= min_len) return m;
    if ((lm > 0) == (la > 0)) {
      a = m;
      la = lm;
    } else {
      b = m;
      lb = lm;
    }
  }
  return std::abs(la) < std::abs(lb) ? a : b;
}

bool IsoField::project_in_plane(Vec3& p, int axis, double max_distance, double tolerance) const {
  const Vec3 start = p;
  for (int it = 0; it < 30; ++it) {
    Vec3 g;
    const double l = level(p, g);
    if (std::abs(l) <= tolerance) return true;
    g[axis] = 0;
    const double g2 = g.squaredNorm();
    const double room = max_distance - (p - start).norm();
    if (!(g2 > 0) || !(room > 0)) return false;
    Vec3 step = -l * g / g2;
    if (step.norm() > room) step *= room / step.norm();
    const Vec3 z = p + step;
    if ((level(z) > 0) != (l > 0)) {
      p = root_on_segment(p, z, tolerance);
      return std::abs(level(p)) <= tolerance;
    }
    p = z;
  }
  return false;
}

bool IsoField::project(Vec3& p, double max_distance, double tolerance) const {
  const Vec3 start = p;
  Vec3 g;
  double l = level(p, g);
  Vec3 best = p;
  double best_l = std::abs(l);
  for (int it = 0; it < 60 && best_l > tolerance; ++it) {
    const double g2 = g.squaredNorm();
    if (g2 == 0) break;
    Vec3 step = -l * g / g2;
    // Stay within the allowed distance of the start, in a few Newton-sized strides.
    const double room = max_distance - (p - start).norm();
    if (room <= 0) break;
    if (step.norm() > room) step *= room / step.norm();
    const Vec3 q = p + step;
    Vec3 gq;
    const double lq = level(q, gq);
    if ((lq > 0) != (l > 0) && lq != 0) {
      best = root_on_segment(p, q, tolerance);
      best_l = std::abs(level(best));
      break;
    }
    p = q;
    l = lq;
    g = gq;
    if (std::abs(l) < best_l) {
      best = p;
      best_l = std::abs(l);
    }
  }
  p = best;
  return best_l <= tolerance;
}

}  // namespace isohex
