#pragma once
/// \file jacobian_bounds.hpp
/// \brief Certified validity of trilinear hexes: bounds of det J over the whole element.
///
/// A hex with corners P_k (VTK order) is the trilinear map x(u,v,w) of the unit cube. Its
/// Jacobian determinant det J(u,v,w) = x_u · (x_v × x_w) is a triquadratic polynomial, so it
/// has exactly 27 coefficients in the tensor Bernstein basis of degree (2,2,2). Bernstein
/// polynomials are non-negative and sum to one, hence min and max of the coefficients bound
/// det J over the element from below and above; the 8 corner coefficients are det J at the
/// corners themselves (the corner Jacobians of Verdict's frames). All 27 coefficients > 0
/// certifies the element valid everywhere; if some are not, subdividing the parameter box
/// (the coefficients of a sub-box are obtained from det J sampled on its 3×3×3 lattice)
/// tightens the bounds until the sign is decided (Johnen, Remacle & Geuzaine, "Geometrical
/// validity of curvilinear finite elements", J. Comput. Phys. 2013, as Gmsh does).
///
/// Verdict's scaled Jacobian samples det J at the 8 corners and the centre only; a hex whose
/// nine samples are positive can still fold inside (a "bow tie": vertices thrown across the
/// element), which a solver integrating at Gauss points rejects. These functions see it.

#include "isohex/mesh/hex_mesh.hpp"

#include <array>
#include <cstddef>
#include <vector>

namespace isohex {

/// det J of the trilinear hex p at parameters (u, v, w) in [0,1]^3 (units of length^3).
double jacobian_determinant(const std::array<Vec3, 8>& p, double u, double v, double w);

/// The 27 Bernstein coefficients of det J over the parameter box [lo, hi] (index
/// i + 3 j + 9 k for degrees i, j, k in u, v, w; the corners are the coefficients with i, j,
/// k in {0, 2}).
std::array<double, 27> jacobian_bernstein(const std::array<Vec3, 8>& p, const Vec3& lo = Vec3::Zero(),
                                          const Vec3& hi = Vec3::Ones());

/// In place: values of a triquadratic at the 3×3×3 lattice of a box (index i + 3j + 9k for
/// the point (i/2, j/2, k/2)) to its Bernstein coefficients. Linear, so it also carries the
/// gradients of such values (one component at a time).
void lattice_to_bernstein(std::array<double, 27>& f);

/// Bounds of det J over the whole element, from adaptive Bernstein subdivision.
struct JacobianBounds {
  double min_lower = 0;  ///< certified: det J >= min_lower everywhere in the element
  double min_upper = 0;  ///< attained: det J takes this value at a point of the element
  double max_lower = 0;  ///< attained: det J takes this value at a point of the element
  double max_upper = 0;  ///< certified: det J <= max_upper everywhere
  int subdivisions = 0;  ///< boxes split to reach the answer (0: the element's 27 coefficients sufficed)
  /// Certified valid: det J > 0 everywhere (min_lower > 0).
  bool valid() const { return min_lower > 0; }
  /// Proven not valid: det J <= 0 at some point (min_upper <= 0).
  bool invalid() const { return min_upper <= 0; }
};

/// Options of jacobian_bounds().
struct JacobianBoundOptions {
  /// Refine until both gaps (min_upper − min_lower and max_upper − max_lower) are at most
  /// this fraction of max |det J| seen ...
  double tolerance = 1e-3;
  /// ... or this many boxes have been split (the bounds stay certified either way).
  int max_subdivisions = 512;
  /// Stop as soon as the sign of the minimum is decided (faster; the gaps may stay wide).
  bool sign_only = false;
};

/// Certified lower and upper bounds of the minimum and maximum of det J over the element.
JacobianBounds jacobian_bounds(const std::array<Vec3, 8>& p, const JacobianBoundOptions& options = {});

/// Gmsh's minJ/maxJ: min det J / max det J over the whole element, here as the certified
/// bounds min_lower / max_upper (a lower bound of the true ratio when both are positive,
/// within `tolerance` of it). 1 for any parallelepiped; <= 0 for an element that is not valid
/// inside; 0 for a flat or collapsed element (max det J = 0).
double jacobian_ratio(const std::array<Vec3, 8>& p);

/// The smallest det J at the 2×2×2 Gauss points, where a solver's C3D8 element (full
/// integration) evaluates it (units of length^3).
double gauss_min_jacobian(const std::array<Vec3, 8>& p);

/// The subdivisions certified_valid() tries before it calls an element undecided (not valid).
inline constexpr int kCertifySubdivisions = 64;

/// True when the element is certified valid with det J >= `floor` everywhere: the 27
/// Bernstein coefficients of the element, and if needed of up to `max_subdivisions` sub-boxes,
/// are all >= floor. Sufficient, never optimistic: false when undecided. The cheap test that
/// the optimisers run on every move.
bool certified_valid(const std::array<Vec3, 8>& p, double floor = 0, int max_subdivisions = kCertifySubdivisions);

/// Verdict's scaled Jacobian where the element is certified valid inside (certified_valid()),
/// and min(scaled Jacobian, 0) where it is not: the measure every optimisation stage keeps, so
/// that raising it can never buy Verdict's nine samples with a fold inside. Degenerate
/// elements keep Verdict's 1e30 marker.
double certified_scaled_jacobian(const std::array<Vec3, 8>& p);

/// The smallest ratio of the 27 Bernstein coefficients of det J, min / max, over the whole
/// element: a certified lower bound of jacobian_ratio() without subdivision (cheap enough for
/// every trial move); <= 0 when the coefficients do not certify the element.
double jacobian_ratio_bound(const std::array<Vec3, 8>& p);

/// `!(jacobian_ratio_bound(p) < ratio_floor) && certified_valid(p, floor)` from one evaluation
/// of the coefficients (each line-search step of the shape stage tests both, hex by hex). With
/// `ratio`, jacobian_ratio_bound(p) is stored there (the same bits) whatever the answer.
bool certified_valid_above_ratio(const std::array<Vec3, 8>& p, double floor, double ratio_floor,
                                 double* ratio = nullptr);

// ---- whole meshes ---------------------------------------------------------------------

/// Per-hex certified validity, ratio and Gauss-point minimum, in hex order (parallel,
/// bit-identical for any thread count).
struct MeshJacobians {
  std::vector<double> ratio;      ///< jacobian_ratio() of each hex
  std::vector<double> gauss_min;  ///< gauss_min_jacobian() of each hex
  std::vector<std::uint8_t> valid;  ///< 1: certified valid inside
};
MeshJacobians mesh_jacobians(const HexMesh& mesh);

/// certified_scaled_jacobian() and jacobian_ratio_bound() of one hex from one evaluation of
/// its coefficients (the worst-element pass needs both for every trial move).
struct CertifiedQuality {
  double scaled_jacobian;
  double ratio_bound;
};
CertifiedQuality certified_quality(const std::array<Vec3, 8>& p);

/// certified_scaled_jacobian() of every hex (parallel, bit-identical for any thread count).
std::vector<double> certified_scaled_jacobians(const HexMesh& mesh);

/// The volume of the hexes against the volume their boundary encloses. Signed volumes of a
/// conforming mesh always add up to the enclosed volume (the interior faces cancel), so the
/// overlap test integrates |det J|: hexes that fold or overlap count their folded parts twice.
struct VolumeBalance {
  double hexes = 0;       ///< Σ ∫ |det J| over the hexes (Gauss 4×4×4 where det J changes sign)
  double signed_hexes = 0;  ///< Σ of the signed hex volumes
  double enclosed = 0;    ///< the volume enclosed by the boundary quads (bilinear patches, exact)
  /// (hexes − enclosed) / enclosed: 0 for a mesh that covers its domain once.
  double excess() const { return enclosed != 0 ? (hexes - enclosed) / enclosed : 0; }
};
VolumeBalance volume_balance(const HexMesh& mesh);

}  // namespace isohex
