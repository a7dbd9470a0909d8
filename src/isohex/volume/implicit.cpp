// Implicit shapes: validation, signed distances, bounds, printing and sampling.
#include "isohex/volume/implicit.hpp"

#include "isohex/error.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace isohex {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void require_positive(double v, std::string_view what) {
  if (!(v > 0) || !std::isfinite(v)) throw Error(fmt::format("{} {} is not a positive number", what, v));
}

void require_finite(const Vec3& v, std::string_view what) {
  if (!v.allFinite()) throw Error(fmt::format("{} ({}, {}, {}) is not finite", what, v.x(), v.y(), v.z()));
}

Shape combine(CsgOp op, std::vector<Shape> operands, std::string_view name) {
  if (operands.size() < 2) throw Error(fmt::format("{} needs at least two shapes, got {}", name, operands.size()));
  return Shape{Csg{op, std::move(operands)}};
}

// Signed distance to the 2-D box |x| <= hx, |y| <= hy (exact inside and outside).
double box2(double x, double y, double hx, double hy) {
  const double qx = std::abs(x) - hx, qy = std::abs(y) - hy;
  return std::hypot(std::max(qx, 0.0), std::max(qy, 0.0)) + std::min(std::max(qx, qy), 0.0);
}

// Half the extent along each axis of a disc of radius r normal to unit vector n.
Vec3 disc_extent(const Vec3& n, double r) {
  return Vec3(r * std::sqrt(std::max(0.0, 1 - n.x() * n.x())), r * std::sqrt(std::max(0.0, 1 - n.y() * n.y())),
              r * std::sqrt(std::max(0.0, 1 - n.z() * n.z())));
}

struct Distance {
  const Vec3& p;
  double operator()(const Sphere& s) const { return (p - s.center).norm() - s.radius; }
  double operator()(const Box& b) const {
    const Vec3 q = (p - 0.5 * (b.lo + b.hi)).cwiseAbs() - 0.5 * (b.hi - b.lo);
    return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
  }
  double operator()(const Cylinder& c) const {
    // In the axis' frame the cylinder is the 2-D box |radial| <= r, |axial - L/2| <= L/2.
    const Vec3 ab = c.b - c.a, ap = p - c.a;
    const double length = ab.norm();
    const Vec3 u = ab / length;
    const double t = ap.dot(u);
    const double radial = (ap - t * u).norm();
    return box2(radial, t - 0.5 * length, c.radius, 0.5 * length);
  }
  double operator()(const Torus& t) const {
    const Vec3 n = t.axis.normalized(), cp = p - t.center;
    const double height = cp.dot(n);
    const double radial = (cp - height * n).norm();
    return std::hypot(radial - t.major, height) - t.minor;
  }
  double operator()(const HalfSpace& h) const { return (p - h.point).dot(h.normal.normalized()); }
  double operator()(const Csg& c) const {
    double d = evaluate(c.operands.front(), p);
    for (std::size_t i = 1; i < c.operands.size(); ++i) {
      const double e = evaluate(c.operands[i], p);
      switch (c.op) {
        case CsgOp::unite: d = std::min(d, e); break;
        case CsgOp::intersect: d = std::max(d, e); break;
        case CsgOp::subtract: d = std::max(d, -e); break;
      }
    }
    return d;
  }
};

struct Bounds {
  Aabb operator()(const Sphere& s) const {
    const Vec3 r = Vec3::Constant(s.radius);
    return {s.center - r, s.center + r};
  }
  Aabb operator()(const Box& b) const { return {b.lo, b.hi}; }
  Aabb operator()(const Cylinder& c) const {
    const Vec3 e = disc_extent((c.b - c.a).normalized(), c.radius);
    return {c.a.cwiseMin(c.b) - e, c.a.cwiseMax(c.b) + e};
  }
  Aabb operator()(const Torus& t) const {
    const Vec3 e = disc_extent(t.axis.normalized(), t.major) + Vec3::Constant(t.minor);
    return {t.center - e, t.center + e};
  }
  Aabb operator()(const HalfSpace& h) const {
    // Bounded on one side along an axis only when the normal is that axis.
    Aabb box{Vec3::Constant(-kInf), Vec3::Constant(kInf)};
    for (int d = 0; d < 3; ++d) {
      const bool along = h.normal[(d + 1) % 3] == 0 && h.normal[(d + 2) % 3] == 0;
      if (along && h.normal[d] > 0) box.hi[d] = h.point[d];
      if (along && h.normal[d] < 0) box.lo[d] = h.point[d];
    }
    return box;
  }
  Aabb operator()(const Csg& c) const {
    Aabb box = bounds(c.operands.front());
    if (c.op == CsgOp::subtract) return box;
    for (std::size_t i = 1; i < c.operands.size(); ++i) {
      const Aabb o = bounds(c.operands[i]);
      if (c.op == CsgOp::unite) box = {box.lo.cwiseMin(o.lo), box.hi.cwiseMax(o.hi)};
      else box = {box.lo.cwiseMax(o.lo), box.hi.cwiseMin(o.hi)};
    }
    return box;
  }
};

// Shortest text that reads back as the same double.
std::string num(double v) { return fmt::format("{}", v); }
std::string nums(const Vec3& v) { return fmt::format("{}, {}, {}", num(v.x()), num(v.y()), num(v.z())); }

struct Printer {
  std::string operator()(const Sphere& s) const { return fmt::format("sphere({}, {})", nums(s.center), num(s.radius)); }
  std::string operator()(const Box& b) const { return fmt::format("box({}, {})", nums(b.lo), nums(b.hi)); }
  std::string operator()(const Cylinder& c) const {
    return fmt::format("cylinder({}, {}, {})", nums(c.a), nums(c.b), num(c.radius));
  }
  std::string operator()(const Torus& t) const {
    if (t.axis == Vec3(0, 0, 1)) return fmt::format("torus({}, {}, {})", nums(t.center), num(t.major), num(t.minor));
    return fmt::format("torus({}, {}, {}, {})", nums(t.center), nums(t.axis), num(t.major), num(t.minor));
  }
  std::string operator()(const HalfSpace& h) const { return fmt::format("plane({}, {})", nums(h.point), nums(h.normal)); }
  std::string operator()(const Csg& c) const {
    std::string s = c.op == CsgOp::unite ? "union(" : c.op == CsgOp::intersect ? "intersection(" : "difference(";
    for (std::size_t i = 0; i < c.operands.size(); ++i) s += (i ? ", " : "") + to_shape_string(c.operands[i]);
    return s + ")";
  }
};

}  // namespace

bool Csg::operator==(const Csg& o) const { return op == o.op && operands == o.operands; }

Shape Shape::sphere(const Vec3& center, double radius) {
  require_finite(center, "sphere centre");
  require_positive(radius, "sphere radius");
  return Shape{Sphere{center, radius}};
}

Shape Shape::box(const Vec3& lo, const Vec3& hi) {
  require_finite(lo, "box corner");
  require_finite(hi, "box corner");
  for (int d = 0; d < 3; ++d)
    if (!(lo[d] < hi[d]))
      throw Error(fmt::format("box: the second corner's {} ({}) is not above the first's ({})", "xyz"[d], hi[d], lo[d]));
  return Shape{Box{lo, hi}};
}

Shape Shape::cylinder(const Vec3& a, const Vec3& b, double radius) {
  require_finite(a, "cylinder end");
  require_finite(b, "cylinder end");
  require_positive(radius, "cylinder radius");
  if (!((b - a).norm() > 0)) throw Error("cylinder: the two ends coincide");
  return Shape{Cylinder{a, b, radius}};
}

Shape Shape::torus(const Vec3& center, const Vec3& axis, double major, double minor) {
  require_finite(center, "torus centre");
  require_finite(axis, "torus axis");
  if (!(axis.norm() > 0)) throw Error("torus: the axis is zero");
  require_positive(major, "torus major radius");
  require_positive(minor, "torus minor radius");
  if (!(minor < major)) throw Error(fmt::format("torus: minor radius {} is not below major radius {}", minor, major));
  return Shape{Torus{center, axis, major, minor}};
}

Shape Shape::plane(const Vec3& point, const Vec3& normal) {
  require_finite(point, "plane point");
  require_finite(normal, "plane normal");
  if (!(normal.norm() > 0)) throw Error("plane: the normal is zero");
  return Shape{HalfSpace{point, normal}};
}

Shape Shape::unite(std::vector<Shape> operands) { return combine(CsgOp::unite, std::move(operands), "union"); }
Shape Shape::intersect(std::vector<Shape> operands) {
  return combine(CsgOp::intersect, std::move(operands), "intersection");
}
Shape Shape::subtract(std::vector<Shape> operands) {
  return combine(CsgOp::subtract, std::move(operands), "difference");
}

double evaluate(const Shape& shape, const Vec3& p) { return std::visit(Distance{p}, shape.node); }

Aabb bounds(const Shape& shape) { return std::visit(Bounds{}, shape.node); }

std::string to_shape_string(const Shape& shape) { return std::visit(Printer{}, shape.node); }

Aabb sampling_bounds(const Shape& shape, double margin_fraction) {
  const Aabb box = bounds(shape);
  for (int d = 0; d < 3; ++d)
    if (!std::isfinite(box.lo[d]) || !std::isfinite(box.hi[d]))
      throw Error(fmt::format("the shape is unbounded along {} (a plane not intersected with a bounded shape): "
                              "give the bounds to sample",
                              "xyz"[d]));
  if (box.is_empty()) throw Error("the shape is empty (an intersection of disjoint bounding boxes)");
  const double margin = margin_fraction * (box.hi - box.lo).maxCoeff();
  return {box.lo - Vec3::Constant(margin), box.hi + Vec3::Constant(margin)};
}

SampleGrid grid_from_dims(const Aabb& box, const std::array<Index, 3>& dims) {
  SampleGrid g;
  for (int d = 0; d < 3; ++d) {
    if (dims[d] < 2) throw Error(fmt::format("grid dims along {} is {}; need at least 2", "xyz"[d], dims[d]));
    if (!(box.hi[d] > box.lo[d]) || !std::isfinite(box.hi[d] - box.lo[d]))
      throw Error(fmt::format("sampling bounds along {} ({} to {}) are empty or not finite", "xyz"[d], box.lo[d], box.hi[d]));
    g.dims[d] = dims[d];
    g.spacing[d] = (box.hi[d] - box.lo[d]) / (dims[d] - 1);
  }
  g.origin = box.lo;
  return g;
}

SampleGrid grid_from_cell_size(const Aabb& box, double cell_size) {
  require_positive(cell_size, "cell size");
  SampleGrid g;
  for (int d = 0; d < 3; ++d) {
    const double extent = box.hi[d] - box.lo[d];
    if (!(extent > 0) || !std::isfinite(extent))
      throw Error(fmt::format("sampling bounds along {} ({} to {}) are empty or not finite", "xyz"[d], box.lo[d], box.hi[d]));
    const double n = std::ceil(extent / cell_size) + 1;
    if (n > double(std::numeric_limits<Index>::max()))
      throw Error(fmt::format("cell size {} gives too many grid points along {}", cell_size, "xyz"[d]));
    g.dims[d] = static_cast<Index>(n);
    g.spacing[d] = cell_size;
    g.origin[d] = 0.5 * (box.lo[d] + box.hi[d]) - 0.5 * (n - 1) * cell_size;
  }
  return g;
}

Volume sample(const Shape& shape, const SampleGrid& grid) {
  Volume v;
  double points = 1;
  for (int d = 0; d < 3; ++d) {
    if (grid.dims[d] < 1) throw Error(fmt::format("grid dims along {} is {}", "xyz"[d], grid.dims[d]));
    if (!(grid.spacing[d] > 0) || !std::isfinite(grid.spacing[d]))
      throw Error(fmt::format("grid spacing along {} ({}) is not positive", "xyz"[d], grid.spacing[d]));
    points *= grid.dims[d];
  }
  if (points > double(std::numeric_limits<Index>::max()))
    throw Error(fmt::format("a grid of {} x {} x {} points is too large (over 2^31)", grid.dims[0], grid.dims[1], grid.dims[2]));
  require_finite(grid.origin, "grid origin");
  v.dims = grid.dims;
  v.spacing = grid.spacing;
  v.origin = grid.origin;
  v.values.resize(v.size());
  tbb::parallel_for(tbb::blocked_range<Index>(0, v.dims[2]), [&](const tbb::blocked_range<Index>& r) {
    for (Index k = r.begin(); k != r.end(); ++k)
      for (Index j = 0; j < v.dims[1]; ++j)
        for (Index i = 0; i < v.dims[0]; ++i) v.at(i, j, k) = static_cast<float>(evaluate(shape, v.point(i, j, k)));
  });
  return v;
}

}  // namespace isohex
