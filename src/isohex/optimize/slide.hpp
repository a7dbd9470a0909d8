#pragma once
/// \file slide.hpp
/// \brief The original boundary of a hex mesh as a surface on which boundary vertices slide
/// during optimisation (`isohex smooth --boundary slide`).
///
/// The boundary quads at construction are split into two triangles each (along the 0–2
/// diagonal) and kept, unchanged, as the target: a sliding vertex's step is made tangential
/// and the result put back on the nearest point of that surface (a uniform grid finds it), so
/// the domain's shape never drifts however many steps are taken. Boundary edges whose two
/// quads meet at more than `feature_degrees` off flat (or that have other than two boundary
/// quads) are feature edges; the vertices on them (feature curves and corners) are pinned.
///
/// Built with an IsoField instead, the target is that field's isosurface (L = 0): a step is made
/// tangential to it (normal −∇L / |∇L| at the vertex) and put back with IsoField::project
/// (reach one local edge length, tolerance 1e-7 × the volume's value range); when the
/// projection fails the step is refused, so a sliding vertex never leaves the isosurface.
/// Boundary vertices not on the isosurface at construction (|L| > 1e-6 × range, e.g. on the
/// volume box's faces), feature vertices, and those of an optional extra mask are pinned.

#include "isohex/contour/iso_field.hpp"
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
  /// empty; one entry per vertex) pins more boundary vertices (e.g. those `isohex mesh` placed
  /// on the domain box).
  BoundarySurface(const HexMesh& mesh, const IsoField& field, double feature_degrees = 30.0,
                  const std::vector<std::uint8_t>* pin = nullptr);

  /// The isosurface's field, or null when sliding on the original boundary triangles.
  [[nodiscard]] const IsoField* field() const { return field_; }
  /// |L| below which a reprojected point counts as on the isosurface (1e-7 × value range).
  [[nodiscard]] double tolerance() const { return tol_; }
  /// The unit normal of the target surface at (or, for the triangles, nearest to) x, in `n`;
  /// false where there is none (a zero gradient): the vertex then must not move.
  bool tangent_normal(const Vec3& x, Vec3& n) const;
  /// Puts `x`, a tangential step from a surface point whose normal is `n`, back on the target
  /// surface; `len` is the local edge length (the isosurface's projection reaches that far).
  /// False when that fails (only for the isosurface): the step must then be refused.
  bool reproject(Vec3& x, const Vec3& n, double len) const;
  /// How far x is from the target: the distance to the triangles, or |L| / value range.
  [[nodiscard]] double deviation(const Vec3& x) const;

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

  std::vector<std::uint8_t> role_;
  const IsoField* field_ = nullptr;
  double tol_ = 0;
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
