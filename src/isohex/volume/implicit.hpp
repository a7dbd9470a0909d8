#pragma once
/// \file implicit.hpp
/// \brief Implicit shapes: primitives and CSG, a small text syntax, signed distances,
/// and sampling onto a Volume.
///
/// A Shape is a tree: primitives at the leaves, union / intersection / difference above.
/// evaluate() returns a signed distance, **negative inside**, zero on the surface: exact
/// for every primitive, and for CSG the usual min / max combination, which is exact
/// outside a union and inside an intersection and elsewhere a bound (|value| never
/// exceeds the true distance). Sampled shapes therefore have their surface at isovalue 0
/// with **inside below the isovalue** (the opposite of molecular densities, where inside
/// is above 1).
///
/// Text syntax (whitespace allowed between any two tokens; numbers are decimal, with an
/// optional sign, fraction and exponent):
///
///     shape := sphere(cx, cy, cz, r)
///            | box(x0, y0, z0, x1, y1, z1)           corners, x0 < x1, y0 < y1, z0 < z1
///            | cylinder(x0, y0, z0, x1, y1, z1, r)   capped, axis from (x0,y0,z0) to (x1,y1,z1)
///            | torus(cx, cy, cz, R, r)               around the z axis, 0 < r < R
///            | torus(cx, cy, cz, ax, ay, az, R, r)   around the axis (ax, ay, az)
///            | plane(px, py, pz, nx, ny, nz)         half-space behind the plane through p
///                                                    with outward normal n
///            | union(shape, shape, ...)              two or more shapes
///            | intersection(shape, shape, ...)
///            | difference(shape, shape, ...)         the first minus all the others
///
/// e.g. `difference(box(-1,-1,-1, 1,1,1), sphere(0,0,0, 1.2))`. Errors throw isohex::Error
/// "shape expression, column C: <what was expected>", C counting characters from 1.
/// to_shape_string() prints a shape back in this syntax, exactly (numbers round-trip).

#include "isohex/volume/volume.hpp"

#include <array>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace isohex {

/// Ball of `radius` about `center`.
struct Sphere {
  Vec3 center{0, 0, 0};
  double radius = 1;
  bool operator==(const Sphere&) const = default;
};

/// Axis-aligned box between corners `lo` < `hi`.
struct Box {
  Vec3 lo{-1, -1, -1}, hi{1, 1, 1};
  bool operator==(const Box&) const = default;
};

/// Finite cylinder with flat caps: the points within `radius` of the segment a-b whose
/// projection onto the line ab falls between a and b.
struct Cylinder {
  Vec3 a{0, 0, -1}, b{0, 0, 1};
  double radius = 1;
  bool operator==(const Cylinder&) const = default;
};

/// Torus: the points within `minor` of the circle of radius `major` about `center` in the
/// plane normal to `axis` (any length; kept as given so text round-trips exactly).
struct Torus {
  Vec3 center{0, 0, 0};
  Vec3 axis{0, 0, 1};
  double major = 2, minor = 0.5;
  bool operator==(const Torus&) const = default;
};

/// Half-space behind the plane through `point`: inside where (p - point)·normal < 0.
/// `normal` may have any length (kept as given).
struct HalfSpace {
  Vec3 point{0, 0, 0};
  Vec3 normal{0, 0, 1};
  bool operator==(const HalfSpace&) const = default;
};

/// Boolean operations; `subtract` removes all later operands from the first.
enum class CsgOp { unite, intersect, subtract };

struct Shape;

/// A Boolean combination of two or more shapes.
struct Csg {
  CsgOp op = CsgOp::unite;
  std::vector<Shape> operands;
  bool operator==(const Csg&) const;
};

/// An implicit shape. Build one with the factories (which validate) or parse_shape().
struct Shape {
  std::variant<Sphere, Box, Cylinder, Torus, HalfSpace, Csg> node;

  bool operator==(const Shape&) const = default;

  /// Factories: throw isohex::Error for a non-positive or non-finite size, a degenerate
  /// axis or normal, r >= R for a torus, or fewer than two CSG operands.
  static Shape sphere(const Vec3& center, double radius);
  static Shape box(const Vec3& lo, const Vec3& hi);
  static Shape cylinder(const Vec3& a, const Vec3& b, double radius);
  static Shape torus(const Vec3& center, const Vec3& axis, double major, double minor);
  static Shape plane(const Vec3& point, const Vec3& normal);
  static Shape unite(std::vector<Shape> operands);
  static Shape intersect(std::vector<Shape> operands);
  static Shape subtract(std::vector<Shape> operands);
};

/// Signed distance from `p` to the shape's surface, negative inside (see the file comment).
double evaluate(const Shape& shape, const Vec3& p);

/// An axis-aligned box; components may be infinite (half-spaces), and lo > hi on some axis
/// means empty.
struct Aabb {
  Vec3 lo, hi;
  [[nodiscard]] bool is_finite() const { return lo.allFinite() && hi.allFinite(); }
  [[nodiscard]] bool is_empty() const { return (lo.array() > hi.array()).any(); }
  /// True when p is in the box, or outside it by at most `slack` along every axis.
  [[nodiscard]] bool contains(const Vec3& p, double slack = 0) const {
    return !((p.array() < lo.array() - slack).any() || (p.array() > hi.array() + slack).any());
  }
};

/// A box containing the shape: tight for the primitives, the union / intersection of the
/// operands' boxes for CSG, the first operand's box for a difference.
Aabb bounds(const Shape& shape);

/// The shape's bounds grown by `margin_fraction` of their largest side on every side, so
/// that the outermost grid points lie strictly outside. Throws isohex::Error if the shape
/// is unbounded (a half-space not intersected with a bounded shape) or empty.
Aabb sampling_bounds(const Shape& shape, double margin_fraction = 0.1);

/// Where to sample: grid point (i, j, k) is at origin + (i·sx, j·sy, k·sz).
struct SampleGrid {
  std::array<Index, 3> dims{2, 2, 2};
  Vec3 spacing{1, 1, 1};
  Vec3 origin{0, 0, 0};
};

/// `dims` points spanning `box` exactly (first and last points on its faces); dims >= 2.
SampleGrid grid_from_dims(const Aabb& box, const std::array<Index, 3>& dims);

/// Points `cell_size` apart covering `box`, centred on it (the grid may overhang `box` by
/// less than a cell on each side).
SampleGrid grid_from_cell_size(const Aabb& box, double cell_size);

/// The signed distance at every grid point (as float), in parallel; the result does not
/// depend on the thread count. Throws isohex::Error for a bad grid or over 2^31 points.
Volume sample(const Shape& shape, const SampleGrid& grid);

/// Parses the text syntax above.
Shape parse_shape(std::string_view text);

/// The shape in the text syntax; parse_shape(to_shape_string(s)) == s.
std::string to_shape_string(const Shape& shape);

}  // namespace isohex
