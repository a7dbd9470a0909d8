#pragma once
/// \file slide.hpp
/// \brief The original boundary of a hex mesh as a surface on which boundary vertices slide
/// during optimisation (`isohex smooth --boundary slide`, `isohex mesh`).
///
/// The boundary quads at construction are split into two triangles each (along the 0–2
/// diagonal) and kept, unchanged, as the target: a sliding vertex's step is made tangential
/// and the result put back on the nearest point of that surface (a uniform grid finds it), so
/// the domain's shape never drifts however many steps are taken. Boundary edges whose two
/// quads meet at more than `feature_degrees` off flat (or that have other than two boundary
/// quads) are feature edges; the vertices on them (feature curves and corners) are pinned.
///
/// Built with level sets instead (contour::LevelSet: isosurfaces, spheres, box faces), each
/// sliding vertex has its own target, the surface its place names: a step is made tangential
/// to that surface (normal −∇L / |∇L| at the vertex) and put back with LevelSet::project (reach
/// one local edge length, to the surface's tolerance: 1e-7 × value range, 1e-10 × radius or box
/// side); when the projection fails the step is refused, so a sliding vertex never leaves its
/// surface. Pinned: boundary vertices whose place is no surface, those not on it at
/// construction (LevelSet::on), those also on another of the surfaces (where two meet:
/// a crease, e.g. a box's edges), feature vertices, and those of an optional extra mask.
/// Except the rim where a curved surface (an isosurface, a sphere) meets one box face: its
/// vertices slide along that curve (on_face()), so that two of them that extraction put next
/// to each other (edges of 1e-6 cells) can move apart.
/// The IsoField form is the one-surface case (every boundary vertex's place is the isosurface).

#include "isohex/contour/iso_field.hpp"
#include "isohex/contour/region.hpp"
#include "isohex/mesh/hex_mesh.hpp"

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace isohex {

class BoundarySurface {
 public:
  /// `loose`: a sliding vertex released by loosen(): it moves freely within a band about its
  /// target surface instead of on it.
  enum class Role : std::uint8_t { interior, slides, pinned, loose };

  explicit BoundarySurface(const HexMesh& mesh, double feature_degrees = 30.0);
  /// Sliding on the isosurface of `field` (which must outlive this). `pin` (may be null or
  /// empty; one entry per vertex) pins more boundary vertices.
  BoundarySurface(const HexMesh& mesh, const IsoField& field, double feature_degrees = 30.0,
                  const std::vector<std::uint8_t>* pin = nullptr);
  /// Sliding on level sets: vertex v on surfaces[place[v]] (a negative place, or a missing
  /// entry, pins a boundary vertex; e.g. contour::ExtractResult::vertex_place, whose
  /// kBoxVertex are pinned unless given a box face of `surfaces`). The fields of isosurfaces
  /// must outlive this.
  BoundarySurface(const HexMesh& mesh, std::vector<contour::LevelSet> surfaces, const std::vector<std::int8_t>& place,
                  double feature_degrees = 30.0, const std::vector<std::uint8_t>* pin = nullptr);

  /// What a vertex keeps to when the places are given one by one (the cut meshes of
  /// sheets/cut.hpp): nothing (kNone: an interior vertex), the triangles of a mesh's boundary
  /// (kTriangles), or surfaces()[k]; with `second` too, the curve where the two meet.
  static constexpr std::int8_t kNone = -1, kTriangles = -2;
  struct Constraint {
    std::int8_t first = kNone, second = kNone;
    bool pinned = false;  ///< held where it is (where three surfaces meet)
    /// For kTriangles: the side of the triangles it keeps to (the triangles facing this way;
    /// zero: the nearest triangle's normal where the vertex is). Both kTriangles: a feature edge
    /// of the triangles, the two faces that meet there (both needed).
    Vec3 facing_first = Vec3::Zero(), facing_second = Vec3::Zero();
  };
  /// Sliding by `constraints` (one per vertex of `mesh`, the mesh to optimise), with the boundary quads
  /// of `triangles_of` (e.g. the mesh before it was cut) as the kTriangles surface. A vertex
  /// with a constraint slides even if it is inside the mesh (a cut surface between two
  /// blocks). Steps along a curve are put back on both surfaces at once (Newton steps on the
  /// two levels, the triangles' by the plane of the nearest one facing the vertex's side).
  BoundarySurface(const HexMesh& mesh, const HexMesh& triangles_of, std::vector<contour::LevelSet> surfaces,
                  const std::vector<Constraint>& constraints);

  /// The level sets vertices slide on (empty when sliding on the original boundary triangles).
  [[nodiscard]] const std::vector<contour::LevelSet>& surfaces() const { return surfaces_; }
  /// The index into surfaces() of sliding vertex v's target, or −1 (not sliding, or triangles).
  [[nodiscard]] int target(Index v) const { return v < static_cast<Index>(target_.size()) ? target_[v] : -1; }
  /// The box face (an index into surfaces()) whose plane sliding vertex v also keeps to: a
  /// rim vertex slides along the curve where its target meets that plane. −1 for the others.
  [[nodiscard]] int on_face(Index v) const { return v < static_cast<Index>(face_.size()) ? face_[v] : -1; }
  /// The second surface a vertex placed by a Constraint keeps to (kNone, kTriangles or an index
  /// into surfaces()).
  [[nodiscard]] int second(Index v) const { return v < static_cast<Index>(second_.size()) ? second_[v] : kNone; }
  /// How many vertices slide on surfaces()[k].
  [[nodiscard]] std::size_t num_sliding_on(std::size_t k) const;
  /// The unit normal of v's target surface at (or, for the triangles, nearest to) x, in `n`;
  /// false where there is none (a zero gradient): the vertex then must not move.
  bool tangent_normal(Index v, const Vec3& x, Vec3& n) const;
  /// Puts `x`, a tangential step of v from a surface point whose normal is `n`, back on v's
  /// target surface; `len` is the local edge length (a level set's projection reaches that far).
  /// False when that fails (only for level sets): the step must then be refused.
  bool reproject(Index v, Vec3& x, const Vec3& n, double len) const;
  /// How far x is from v's target: the distance to the triangles, or |L| / scale.
  [[nodiscard]] double deviation(Index v, const Vec3& x) const;

  /// Releases the sliding vertices among `vertices` (interior ones are ignored) into a band of
  /// half-width `band` (world units) about their target: they step freely in space and are
  /// clamped back into the band (band_clamp). For a boundary that, kept exactly on the
  /// isosurface, leaves elements that no interior placement can make valid: a knife edge
  /// one voxel thick, whose quads face opposite ways at a vertex. Returns how many were released.
  /// Pinned vertices are released too where they have a surface to keep near: about the
  /// input's triangles (feature vertices), or about the isosurface they lie on (a rim, where it
  /// meets the domain box). Not released: vertices on a shape (a cut surface) or on its curve
  /// with another surface, and the pinned ones of the Constraint form (corners); after
  /// set_release_creases(true), a vertex on a cut's curve with an isosurface is released about
  /// the isosurface and stays on the cut.
  std::size_t loosen(const HexMesh& mesh, const std::vector<Index>& vertices, double band);
  /// Lets loosen() release the vertices where a cut meets an isosurface (the last resort of
  /// `isohex mesh --cut`: their hexes stayed below 0.2 with the crease on the isosurface).
  void set_release_creases(bool on) { release_creases_ = on; }
  /// Makes surfaces()[k] for k >= `first` exact like a shape (loosen() never releases a vertex
  /// on one): the cuts along a volume's isosurfaces of `isohex mesh --cut-iso`.
  void set_exact_from(int first) { exact_from_ = first; }
  /// True for surfaces()[k] that loosen() keeps exact: a shape's, or from set_exact_from() on.
  [[nodiscard]] bool exact(int k) const {
    return k >= 0 && (k >= exact_from_ || surfaces_[static_cast<std::size_t>(k)].shape() != nullptr);
  }
  /// Where loose vertex v at x would sit on its target (`len`: the local edge length): the
  /// nearest triangle point, a rim vertex's point on its curve, else its foot point on its
  /// level set. False where there is none.
  bool snap(Index v, Vec3& x, double len) const;
  /// Makes loose vertex v, which the caller has put on its target (snap()), slide again. Only
  /// for vertices loosen() released from sliding (false, and nothing changes, for the others:
  /// a pinned vertex's place is not any point of one surface).
  bool reattach(Index v);
  /// The box the moving boundary vertices must stay in (the domain: neither a band nor an
  /// isosurface that goes on past its faces may carry them out of it).
  void set_domain(const Aabb& box) { domain_ = box; has_domain_ = true; }
  /// x within the domain box (1e-9 of its diagonal spare), or no box set. Steps that would put
  /// a vertex on its surface outside it are refused.
  [[nodiscard]] bool in_domain(const Vec3& x) const;
  /// Puts x, a step of loose vertex v (local edge length `len`), back within the band: into the
  /// domain box if one is set, then x's foot point on v's target (the level set's projection,
  /// or the nearest triangle point) and, if x is farther than the band from it, the point at
  /// the band's distance towards x, into the box again, a few rounds. False when the foot point
  /// cannot be found or does not settle: the step must then be refused.
  bool band_clamp(Index v, Vec3& x, double len) const;
  /// Puts x, a step of v from a point whose tangent-plane normal is `n`, back where v's role
  /// allows: reproject() for a sliding vertex, band_clamp() for a loose one, unchanged for the
  /// others. False: the step must be refused.
  bool put_back(Index v, Vec3& x, const Vec3& n, double len) const;
  /// The distance from x to its foot point on v's target (world units; 0 if there is none).
  [[nodiscard]] double offset(Index v, const Vec3& x) const;
  /// How well `mesh` keeps to the surface: the largest deviation() of a sliding vertex and the
  /// largest offset() of a loose one.
  struct Fit {
    double max_deviation = 0, max_offset = 0;
  };
  [[nodiscard]] Fit fit(const HexMesh& mesh) const;
  [[nodiscard]] std::size_t num_loose() const { return loose_; }
  /// True for a vertex that moves with its surface: sliding on it or loose about it.
  [[nodiscard]] bool moves_with_surface(Index v) const {
    return role_[v] == static_cast<std::uint8_t>(Role::slides) || role_[v] == static_cast<std::uint8_t>(Role::loose);
  }

  [[nodiscard]] Role role(Index v) const { return static_cast<Role>(role_[v]); }
  /// What loosen() and reattach() change (each vertex's role and target, the band), to be put
  /// back with set_roles(): a few bytes a vertex, where a copy of the whole surface would
  /// carry its triangles and grid too.
  struct Roles {
    std::vector<std::uint8_t> role, unpinned;
    std::vector<std::int8_t> target;
    std::size_t sliding = 0, pinned = 0, loose = 0;
    double band = 0;
  };
  [[nodiscard]] Roles roles() const { return {role_, unpinned_, target_, sliding_, pinned_, loose_, band_}; }
  void set_roles(Roles r) {
    role_ = std::move(r.role), unpinned_ = std::move(r.unpinned), target_ = std::move(r.target);
    sliding_ = r.sliding, pinned_ = r.pinned, loose_ = r.loose, band_ = r.band;
  }
  [[nodiscard]] std::size_t num_sliding() const { return sliding_; }
  [[nodiscard]] std::size_t num_pinned() const { return pinned_; }
  /// The vertices the optimisers must hold: the pinned ones.
  [[nodiscard]] std::vector<std::uint8_t> fixed_mask() const;

  /// The nearest point of the original boundary to x; with `facing`, only among triangles whose
  /// normal has a positive dot product with it (so that a point is never carried across a thin
  /// wall to the other side). `normal` (may be null) receives that triangle's unit normal.
  /// Ties go to the lowest triangle id: deterministic. Returns x if no triangle qualifies.
  Vec3 project(const Vec3& x, const Vec3* facing = nullptr, Vec3* normal = nullptr) const;

  /// The triangles of the original boundary (outward oriented), for tests and diagnostics.
  [[nodiscard]] const std::vector<std::array<Vec3, 3>>& triangles() const { return tris_; }

 private:
  /// v slides on (or is released about) the triangles: the triangle form, or a Constraint's.
  [[nodiscard]] bool on_triangles(Index v) const { return !tris_.empty() && target(v) < 0; }
  /// x onto the curve of v's two constraints (Newton steps within `len`); false if it fails.
  bool project_on_curve(Index v, Vec3& x, double len) const;
  void classify(const HexMesh& mesh, double feature_degrees, bool keep_triangles);
  /// v's foot point on its target from x: projections of growing reach (the first band,
  /// doubled until at or past max_reach; a bracketed sign change after the first); false if
  /// none succeeds.
  bool foot_point(Index v, const Vec3& x, double max_reach, Vec3& foot) const;
  static constexpr double kFootReach = 8;  // × band: the reach from a point within the band
  void assign_targets(const HexMesh& mesh, const std::vector<std::int8_t>& place, const std::vector<std::uint8_t>* pin);

  std::vector<std::uint8_t> role_;
  std::vector<contour::LevelSet> surfaces_;
  std::vector<std::int8_t> target_;  // per vertex: index into surfaces_, −1 unless sliding on one
  std::vector<std::int8_t> face_;    // per vertex: the box face a rim vertex keeps to, or −1
  std::vector<std::int8_t> second_;  // per vertex (or empty): a Constraint's second surface
  std::vector<Vec3> facing_;         // per vertex (or empty): the side of the triangles it keeps to
  std::vector<Vec3> facing2_;        // ... and of the second face, on a feature edge (both triangles)
  std::vector<std::uint8_t> unpinned_;  // per vertex (or empty): loosen() released it from pinned
  std::size_t sliding_ = 0, pinned_ = 0, loose_ = 0;
  double band_ = 0;
  double reach_unit_ = 0;  // the first band loosen() set: foot_point()'s first reach
  bool release_creases_ = false;
  int exact_from_ = std::numeric_limits<int>::max();
  Aabb domain_{Vec3::Zero(), Vec3::Zero()};
  bool has_domain_ = false;
  std::vector<std::array<Vec3, 3>> tris_;
  std::vector<Vec3> normals_;
  // Uniform grid over the triangles' bounding box: cell c holds items[start[c] .. start[c+1]).
  Vec3 lo_ = Vec3::Zero(), hi_ = Vec3::Zero();
  double cell_ = 1;
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<std::size_t> start_;
  std::vector<std::uint32_t> items_;
};

}  // namespace isohex
