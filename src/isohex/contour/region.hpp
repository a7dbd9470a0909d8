#pragma once
/// \file region.hpp
/// \brief The solid to mesh, as an intersection of level sets inside a box: the inside of an
/// isosurface, the outside of one up to an outer sphere or box, or the shell between two.
///
/// A Region is a *domain* box and a list of surfaces, each a level set L_k positive inside.
/// A point is inside the region when it lies in the domain box (faces included) and every
/// L_k(p) > 0 (i.e. min_k L_k > 0). A point with some L_k(p) == 0 is on that surface and
/// counts as outside, in every stage: the solid is the open set {L > 0}, as in
/// isohex::is_inside. The domain box closes the solid where it is cut (a CT scan cut at the
/// neck is closed by the box's bottom face).

#include "isohex/contour/iso_field.hpp"
#include "isohex/volume/implicit.hpp"

#include <cmath>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace isohex::contour {

/// One bounding surface of a region: an isosurface of the volume or an analytic sphere; or a
/// face of a box, which no Region holds (the box is its domain) but on which boundary vertices
/// slide during optimisation (optimize/slide.hpp) like on the others.
class LevelSet {
 public:
  /// The level set of `field` (which the LevelSet shares).
  explicit LevelSet(std::shared_ptr<const IsoField> field);
  /// The ball of `radius` about `center`: L = radius − |p − center|.
  LevelSet(const Vec3& center, double radius);
  /// Face `face` of `box` (axis face / 2, the upper side if face is odd): L is the signed
  /// distance to its plane, positive towards the box; project() only succeeds within the face
  /// (its edges included), so a point never slides off it onto a neighbouring face.
  LevelSet(const Aabb& box, int face);
  /// The surface of an implicit shape (implicit.hpp), positive inside: L = −evaluate(shape, p),
  /// a signed distance (exact for a primitive, a bound near CSG creases). `scale` is the unit
  /// of relative distances (e.g. the size of the mesh it cuts); the tolerance is 1e-10 of it.
  LevelSet(std::shared_ptr<const Shape> shape, double scale);

  /// L(p). For an isosurface whose interpolant is exact at grid points (trilinear, cubic),
  /// a point within 1e-9 cells of a grid point takes the stored value exactly, so that
  /// classification and root finding agree on the sign of L at sampled points.
  [[nodiscard]] double level(const Vec3& p) const;
  /// L(p) and its gradient.
  double level(const Vec3& p, Vec3& gradient) const;
  /// The zero of L on [a, b], given L(a) > 0 ≥ L(b); an endpoint within `tolerance` of the
  /// surface is returned as is.
  [[nodiscard]] Vec3 root(const Vec3& a, const Vec3& b) const;
  /// Moves `p` onto the surface, at most `max_distance` away; true on success (|L| ≤ tolerance).
  bool project(Vec3& p, double max_distance) const;
  /// Moves `p` to the nearest sign change of L found along the gradient's direction and the
  /// three axes, both ways, at distances doubling from max_distance / 16 to `max_distance`,
  /// bisected onto the surface; true on success. Slower than project() but sure where it
  /// finds a change: on a scan's isosurface a plateau of values just off the isovalue can
  /// send Newton's steps far from a surface that lies close by.
  bool bracket(Vec3& p, double max_distance) const;
  /// |L| below which a point counts as on the surface: 1e-7 of the volume's value range
  /// (so |f − iso| ≤ 1e-7 × range), or 1e-10 of a sphere's radius or a box's largest side.
  [[nodiscard]] double tolerance() const { return tolerance_; }
  /// True if p counts as on the surface for a mesh vertex placed there (a sliding vertex's
  /// start): |L| ≤ 10 × tolerance, i.e. 1e-6 × range, 1e-9 × radius or side.
  [[nodiscard]] bool on(const Vec3& p) const { return std::abs(level(p)) <= 10 * tolerance_; }
  /// The unit of relative distances: the value range of an isosurface, a sphere's radius, a
  /// box's largest side.
  [[nodiscard]] double scale() const { return scale_; }
  /// The box face (0–5) of a box-face level set, −1 for the others.
  [[nodiscard]] int box_face() const { return face_; }
  /// Moves `p` onto this surface and the plane of box face `plane` at once (their curve of
  /// intersection, e.g. an isosurface's rim on the domain box), at most `max_distance` away:
  /// onto the plane exactly, then Newton steps along the gradient's component in the plane.
  /// True on success (|L| ≤ tolerance, p within the face).
  bool project_on_face(Vec3& p, double max_distance, const LevelSet& plane) const;
  /// The isosurface's field, or null for a sphere or a box face.
  [[nodiscard]] const IsoField* field() const { return field_.get(); }
  /// The implicit shape, or null for the others.
  [[nodiscard]] const Shape* shape() const { return shape_.get(); }
  /// "isosurface 1150 (inside above)", "sphere (...) radius R", "box face z = 0" or "shape EXPR".
  [[nodiscard]] std::string describe() const;

 private:
  bool project_shape(Vec3& p, double max_distance) const;

  std::shared_ptr<const IsoField> field_;
  std::shared_ptr<const Shape> shape_;
  bool snap_to_grid_ = false;
  Vec3 center_{0, 0, 0};
  double radius_ = 0;
  int face_ = -1;  // a box face (0–5), or −1
  Aabb box_{Vec3::Zero(), Vec3::Zero()};
  double tolerance_ = 0;
  double scale_ = 1;
};

/// A solid to mesh.
struct Region {
  Aabb domain;                    ///< the sampled box; points outside are outside
  std::vector<LevelSet> surfaces; ///< inside = every level positive
  /// min_k L_k(p) (without the domain box).
  [[nodiscard]] double level(const Vec3& p) const;
};

/// The six faces of `box` as level sets (LevelSet(box, 0..5)).
std::vector<LevelSet> box_faces(const Aabb& box);

/// Which part of space around the isosurface to mesh.
enum class RegionKind : unsigned char { inside, outside, between };
std::string_view region_name(RegionKind k);
std::optional<RegionKind> region_from_name(std::string_view name);

/// The outer boundary of RegionKind::outside.
struct OuterBoundary {
  enum class Kind : unsigned char { volume_box, sphere, box } kind = Kind::volume_box;
  Vec3 center{0, 0, 0};
  double radius = 0;
  Aabb box{Vec3::Zero(), Vec3::Zero()};
};
/// Parses "sphere:CX,CY,CZ,R" or "box:X0,Y0,Z0,X1,Y1,Z1"; throws isohex::Error.
OuterBoundary parse_outer(std::string_view text);

/// What to mesh, in terms of a volume.
struct RegionSpec {
  RegionKind kind = RegionKind::inside;
  double isovalue = 0;
  Inside inside = Inside::above;        ///< for inside/outside; `between` ignores it
  double isovalue2 = 0;                 ///< the second isovalue of `between`
  Interpolation interpolation = Interpolation::trilinear;
  OuterBoundary outer;                  ///< for `outside`
};

/// Builds the region: `inside` = {L > 0} in the volume's box; `outside` = {L < 0} within the
/// outer boundary (the volume's box by default; a sphere or box may reach beyond the volume,
/// where the field continues as its value on the box, see isohex::sample); `between` = the
/// values strictly between the two isovalues, in the volume's box. `volume` must outlive the
/// region. Throws isohex::Error for inconsistent specs (equal isovalues, empty outer box, ...).
Region make_region(const Volume& volume, const RegionSpec& spec);

}  // namespace isohex::contour
