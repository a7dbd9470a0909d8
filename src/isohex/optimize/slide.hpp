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
/// The IsoField form is the one-surface case (every boundary vertex's place is the isosurface).

#include "isohex/contour/iso_field.hpp"
#include "isohex/contour/region.hpp"
#include "isohex/mesh/hex_mesh.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace isohex {

class BoundarySurface {
 public:
  enum class Role : std::uint8_t { interior, slides, pinned };

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

  /// The level sets vertices slide on (empty when sliding on the original boundary triangles).
  [[nodiscard]] const std::vector<contour::LevelSet>& surfaces() const { return surfaces_; }
  /// The index into surfaces() of sliding vertex v's target, or −1 (not sliding, or triangles).
  [[nodiscard]] int target(Index v) const { return v < static_cast<Index>(target_.size()) ? target_[v] : -1; }
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

  [[nodiscard]] Role role(Index v) const { return static_cast<Role>(role_[v]); }
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
  void classify(const HexMesh& mesh, double feature_degrees, bool keep_triangles);
  void assign_targets(const HexMesh& mesh, const std::vector<std::int8_t>& place, const std::vector<std::uint8_t>* pin);

  std::vector<std::uint8_t> role_;
  std::vector<contour::LevelSet> surfaces_;
  std::vector<std::int8_t> target_;  // per vertex: index into surfaces_, −1 unless sliding on one
  std::size_t sliding_ = 0, pinned_ = 0;
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
