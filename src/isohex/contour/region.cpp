#include "isohex/contour/region.hpp"

#include "isohex/error.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

namespace isohex::contour {

LevelSet::LevelSet(std::shared_ptr<const IsoField> field) : field_(std::move(field)) {
  // The smoothing spline does not pass through the samples, so it is never snapped.
  snap_to_grid_ = field_->interpolation() != Interpolation::smooth_cubic;
  const double range = field_->value_range() > 0 ? field_->value_range() : std::max(1.0, std::abs(field_->isovalue()));
  scale_ = range;
  tolerance_ = 1e-7 * range;
}

LevelSet::LevelSet(const Vec3& center, double radius) : center_(center), radius_(radius), tolerance_(1e-10 * radius), scale_(radius) {}

LevelSet::LevelSet(const Aabb& box, int face) : face_(face), box_(box) {
  if (face < 0 || face > 5 || box.is_empty() || !box.is_finite()) throw Error("LevelSet: a box face needs face 0-5 of a finite box");
  scale_ = (box.hi - box.lo).maxCoeff();
  tolerance_ = 1e-10 * scale_;
}

LevelSet::LevelSet(std::shared_ptr<const Shape> shape, double scale) : shape_(std::move(shape)) {
  if (!shape_ || !(scale > 0) || !std::isfinite(scale)) throw Error("LevelSet: a shape needs a positive, finite scale");
  scale_ = scale;
  tolerance_ = 1e-10 * scale;
}

namespace {
// A box face's inward unit normal: +e_a on the lower side, −e_a on the upper.
Vec3 face_normal(int face) {
  Vec3 n = Vec3::Zero();
  n[face / 2] = face % 2 ? -1.0 : 1.0;
  return n;
}
}  // namespace

double LevelSet::level(const Vec3& p) const {
  if (face_ >= 0) return face_ % 2 ? box_.hi[face_ / 2] - p[face_ / 2] : p[face_ / 2] - box_.lo[face_ / 2];
  if (shape_) return -evaluate(*shape_, p);
  if (!field_) return radius_ - (p - center_).norm();
  if (snap_to_grid_) {
    const Volume& v = field_->volume();
    const Vec3 g = grid_coordinates(v, p);
    const Vec3 r = g.array().round();
    if ((g - r).cwiseAbs().maxCoeff() < 1e-9 && (r.array() >= 0).all() && r.x() < v.dims[0] && r.y() < v.dims[1] &&
        r.z() < v.dims[2])
      return inside_level(v.at(static_cast<Index>(r.x()), static_cast<Index>(r.y()), static_cast<Index>(r.z())),
                          field_->isovalue(), field_->inside());
  }
  return field_->level(p);
}

double LevelSet::level(const Vec3& p, Vec3& gradient) const {
  if (face_ >= 0) {
    gradient = face_normal(face_);
    return level(p);
  }
  if (shape_) {
    // Central differences: the distance is piecewise smooth, and a step of 1e-7 of the scale
    // keeps both the truncation and the rounding error near 1e-9 of the gradient.
    const double h = 1e-7 * scale_;
    for (int j = 0; j < 3; ++j) {
      Vec3 a = p, b = p;
      a[j] += h, b[j] -= h;
      gradient[j] = (level(a) - level(b)) / (2 * h);
    }
    return level(p);
  }
  if (!field_) {
    const Vec3 d = p - center_;
    const double n = d.norm();
    gradient = n > 0 ? Vec3(-d / n) : Vec3(0, 0, 0);
    return radius_ - n;
  }
  const double l = field_->level(p, gradient);
  return snap_to_grid_ ? level(p) : l;
}

Vec3 LevelSet::root(const Vec3& a, const Vec3& b) const {
  if (std::abs(level(b)) <= tolerance_) return b;
  if (std::abs(level(a)) <= tolerance_) return a;
  if (field_) return field_->root_on_segment(a, b, tolerance_);
  if (shape_) {
    Vec3 lo = a, hi = b;  // L(lo) > 0 >= L(hi)
    for (int it = 0; it < 200 && std::abs(level(hi)) > tolerance_; ++it) {
      const Vec3 mid = 0.5 * (lo + hi);
      (level(mid) > 0 ? lo : hi) = mid;
      if ((hi - lo).norm() <= 1e-12 * (b - a).norm()) break;
    }
    return hi;
  }
  if (face_ >= 0) {
    const double la = level(a), lb = level(b);
    return a + std::clamp(la / (la - lb), 0.0, 1.0) * (b - a);
  }
  // Sphere: |a + t (b − a) − c| = r, the root in [0, 1] (a is inside).
  const Vec3 d = b - a, o = a - center_;
  const double qa = d.squaredNorm(), qb = 2 * o.dot(d), qc = o.squaredNorm() - radius_ * radius_;
  const double t = (-qb + std::sqrt(std::max(0.0, qb * qb - 4 * qa * qc))) / (2 * qa);
  return a + std::clamp(t, 0.0, 1.0) * d;
}

bool LevelSet::project_on_face(Vec3& p, double max_distance, const LevelSet& plane) const {
  if (plane.face_ < 0 || face_ >= 0) return false;
  Vec3 q = p;
  if (!plane.project(q, max_distance)) return false;
  const int a = plane.face_ / 2;
  const Vec3 start = q;
  for (int it = 0; it < 40; ++it) {
    Vec3 g;
    const double l = level(q, g);
    if (std::abs(l) <= tolerance_) {
      if (!((q - p).norm() <= max_distance) || !plane.project(q, 0)) return false;  // still within the face
      p = q;
      return true;
    }
    g[a] = 0;
    const double gg = g.squaredNorm();
    if (!(gg > 0)) return false;
    q -= (l / gg) * g;
    if (!((q - start).norm() <= max_distance)) return false;
  }
  return false;
}

bool LevelSet::project(Vec3& p, double max_distance) const {
  if (face_ >= 0) {
    // Onto the plane exactly, and only within the face: past its edges lies another face.
    const int a = face_ / 2;
    if (!(std::abs(level(p)) <= max_distance)) return false;
    for (int j = 0; j < 3; ++j)
      if (j != a && !(p[j] >= box_.lo[j] && p[j] <= box_.hi[j])) return false;
    p[a] = face_ % 2 ? box_.hi[a] : box_.lo[a];
    return true;
  }
  if (std::abs(level(p)) <= tolerance_) return true;
  if (field_) return field_->project(p, max_distance, tolerance_);
  if (shape_) return project_shape(p, max_distance);
  const Vec3 d = p - center_;
  const double n = d.norm();
  if (n == 0 || std::abs(n - radius_) > max_distance) return false;
  p = center_ + d * (radius_ / n);
  return true;
}

bool LevelSet::bracket(Vec3& p, double max_distance) const {
  Vec3 g;
  const double l0 = level(p, g);
  if (std::abs(l0) <= tolerance_) return true;
  std::vector<Vec3> dirs = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
  if (g.norm() > 0) dirs.insert(dirs.begin(), g.normalized());
  for (double t = max_distance / 16; t <= max_distance * (1 + 1e-12); t *= 2) {
    double best = std::numeric_limits<double>::infinity();
    Vec3 found = p;
    for (const Vec3& d : dirs)
      for (const double sign : {1.0, -1.0}) {
        const Vec3 y = p + sign * t * d;
        if ((level(y) > 0) == (l0 > 0)) continue;
        const Vec3 r = l0 > 0 ? root(p, y) : root(y, p);
        if ((r - p).norm() < best) best = (r - p).norm(), found = r;
      }
    if (best < std::numeric_limits<double>::infinity()) {
      p = found;
      return true;
    }
  }
  return false;
}

bool LevelSet::project_shape(Vec3& p, double max_distance) const {
  // Newton steps along the gradient (one step for a plane or a sphere: L is a distance); a
  // step that overshoots a kink of a CSG distance is halved until |L| falls.
  Vec3 q = p;
  for (int it = 0; it < 60; ++it) {
    Vec3 g;
    const double l = level(q, g);
    if (std::abs(l) <= tolerance_) {
      if (!((q - p).norm() <= max_distance)) return false;
      p = q;
      return true;
    }
    const double gg = g.squaredNorm();
    if (!(gg > 0)) return false;
    Vec3 step = (l / gg) * g;
    Vec3 next = q - step;
    for (int half = 0; half < 30 && !(std::abs(level(next)) < std::abs(l)); ++half) next = q - (step *= 0.5);
    q = next;
    if (!((q - p).norm() <= 2 * max_distance)) return false;
  }
  return false;
}

std::string LevelSet::describe() const {
  if (shape_) return fmt::format("shape {}", to_shape_string(*shape_));
  if (face_ >= 0)
    return fmt::format("box face {} = {:g}", "xyz"[face_ / 2], face_ % 2 ? box_.hi[face_ / 2] : box_.lo[face_ / 2]);
  if (!field_) return fmt::format("sphere ({:g}, {:g}, {:g}) radius {:g}", center_.x(), center_.y(), center_.z(), radius_);
  return fmt::format("isosurface {:g} (inside {})", field_->isovalue(), inside_name(field_->inside()));
}

double Region::level(const Vec3& p) const {
  double l = std::numeric_limits<double>::infinity();
  for (const LevelSet& s : surfaces) l = std::min(l, s.level(p));
  return l;
}

std::vector<LevelSet> box_faces(const Aabb& box) {
  std::vector<LevelSet> faces;
  for (int f = 0; f < 6; ++f) faces.emplace_back(box, f);
  return faces;
}

std::string_view region_name(RegionKind k) {
  switch (k) {
    case RegionKind::inside: return "inside";
    case RegionKind::outside: return "outside";
    case RegionKind::between: return "between";
  }
  return "inside";
}

std::optional<RegionKind> region_from_name(std::string_view name) {
  for (RegionKind k : {RegionKind::inside, RegionKind::outside, RegionKind::between})
    if (region_name(k) == name) return k;
  return std::nullopt;
}

namespace {

std::vector<double> parse_numbers(std::string_view text, std::string_view what) {
  std::vector<double> out;
  std::string s(text);
  const char* p = s.c_str();
  while (*p) {
    char* end = nullptr;
    const double v = std::strtod(p, &end);
    if (end == p || !std::isfinite(v)) throw Error(fmt::format("--outer {}: '{}' is not a list of numbers", what, text));
    out.push_back(v);
    p = end;
    if (*p == ',') ++p;
    else if (*p) throw Error(fmt::format("--outer {}: '{}' is not a comma-separated list of numbers", what, text));
  }
  return out;
}

Inside opposite(Inside i) { return i == Inside::above ? Inside::below : Inside::above; }

}  // namespace

OuterBoundary parse_outer(std::string_view text) {
  OuterBoundary o;
  if (text.starts_with("sphere:")) {
    const auto v = parse_numbers(text.substr(7), "sphere");
    if (v.size() != 4 || v[3] <= 0) throw Error("--outer sphere:CX,CY,CZ,R needs 4 numbers and R > 0");
    o.kind = OuterBoundary::Kind::sphere;
    o.center = Vec3(v[0], v[1], v[2]);
    o.radius = v[3];
  } else if (text.starts_with("box:")) {
    const auto v = parse_numbers(text.substr(4), "box");
    if (v.size() != 6 || !(v[0] < v[3] && v[1] < v[4] && v[2] < v[5]))
      throw Error("--outer box:X0,Y0,Z0,X1,Y1,Z1 needs 6 numbers with X0 < X1, Y0 < Y1, Z0 < Z1");
    o.kind = OuterBoundary::Kind::box;
    o.box = Aabb{Vec3(v[0], v[1], v[2]), Vec3(v[3], v[4], v[5])};
  } else {
    throw Error(fmt::format("--outer '{}': expected sphere:CX,CY,CZ,R or box:X0,Y0,Z0,X1,Y1,Z1", text));
  }
  return o;
}

Region make_region(const Volume& volume, const RegionSpec& spec) {
  if (volume.size() == 0) throw Error("cannot mesh an empty volume");
  Region r;
  r.domain = Aabb{volume.origin, volume.max_corner()};
  auto field = [&](double iso, Inside in) {
    return LevelSet(std::make_shared<const IsoField>(volume, iso, in, spec.interpolation));
  };
  switch (spec.kind) {
    case RegionKind::inside: r.surfaces.push_back(field(spec.isovalue, spec.inside)); break;
    case RegionKind::outside:
      r.surfaces.push_back(field(spec.isovalue, opposite(spec.inside)));
      if (spec.outer.kind == OuterBoundary::Kind::sphere) {
        r.surfaces.emplace_back(spec.outer.center, spec.outer.radius);
        r.domain = Aabb{spec.outer.center.array() - spec.outer.radius, spec.outer.center.array() + spec.outer.radius};
      } else if (spec.outer.kind == OuterBoundary::Kind::box) {
        r.domain = spec.outer.box;
      }
      break;
    case RegionKind::between: {
      if (spec.isovalue == spec.isovalue2) throw Error("--region between needs two different isovalues");
      const double lo = std::min(spec.isovalue, spec.isovalue2), hi = std::max(spec.isovalue, spec.isovalue2);
      r.surfaces.push_back(field(lo, Inside::above));
      r.surfaces.push_back(field(hi, Inside::below));
      break;
    }
  }
  return r;
}

}  // namespace isohex::contour
