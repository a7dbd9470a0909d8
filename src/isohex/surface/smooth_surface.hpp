#pragma once
/// \file smooth_surface.hpp
/// \brief Geometric-flow smoothing of a hex mesh's boundary that keeps the boundary on the
/// isosurface (Shepherd et al. 2006 §2.3, after Zhang, Bajaj & Xu 2005).
///
/// Each iteration has three parts, as in LBIE-Mesher's quality improvement:
///  1. **Normal denoising**: a surface-diffusion step (the Laplacian of a discrete mean
///     curvature, H_i = n_i·(c_i − x_i) with c_i the area-weighted centroid of the vertex's
///     boundary quads) along the vertex normal. Surface diffusion preserves the enclosed
///     volume, unlike a plain Laplacian, which shrinks the surface.
///  2. **Tangential relaxation**: each free boundary vertex moves toward c_i projected onto
///     its tangent plane (the plane normal to the field's gradient), which equalises the quads
///     around it without changing the surface's shape.
///  3. **Interior relaxation**: interior vertices within a few hex layers of the boundary
///     move toward the mass centre of their hexes (volume-weighted hex centroids), which
///     makes room for the boundary motion.
/// After every boundary move the vertex is projected back onto the isosurface
/// (IsoField::project), so the boundary never leaves it: the normal step therefore only
/// matters as far as it shifts where the projection lands, and is off by default.
///
/// \par Guarantees
/// Boundary vertices off the isosurface are first projected onto it; such a projection is
/// taken unless it would invert a hex or a boundary quad (reaching the isosurface outranks
/// quality). From this *projected* mesh on, every smoothing move (boundary or interior) is
/// checked against the hexes and boundary quads around the vertex, each against a soft and a
/// hard floor: for hexes `min_hex_sj` and 0, for boundary quads max(`min_quad_sj`, m) and m,
/// m being the smallest boundary-quad scaled Jacobian of the projected mesh. No element may
/// cross either floor downward, and one already below its hard floor may not get worse;
/// between the floors it moves freely (so that a bad element does not freeze its neighbours).
/// A move that fails is halved (and the halved point reprojected) up to `max_halvings`
/// times, then dropped. Hence: the number of inverted hexes never increases, no hex at or
/// above `min_hex_sj` drops below it, and the minimum boundary-quad scaled Jacobian never
/// falls below that of the projected mesh (the input's when the input boundary is on the
/// isosurface already). Verdict's degenerate marker (1e30) counts as 0.
///
/// \par Parallelism
/// Vertices are coloured (greedily, in id order) so that no two vertices of one colour
/// share a hex; the vertices of a colour move in parallel (oneTBB), each reading only
/// vertices of other colours. The result is bit-identical for any thread count.
///
/// \par Pinned vertices and creases
/// Vertices flagged in `mesh.fixed` (when `use_mesh_fixed`) or in `options.pinned` never move,
/// not even onto the isosurface. Boundary vertices on a *crease* (an edge whose two boundary
/// quads' normals differ by more than `crease_angle_degrees`, or a non-manifold boundary edge)
/// are held too, except that they are projected onto the isosurface when they are off it:
/// creases are kept by pinning, not by sliding along the crease line.

#include "isohex/contour/iso_field.hpp"
#include "isohex/mesh/hex_mesh.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace isohex {

/// Parameters of smooth_surface(). The defaults suit meshes from dual contouring.
struct SurfaceSmoothingOptions {
  int iterations = 100;               ///< upper bound on outer iterations (≥ 0); ~100 converge on the test balls
  double tangential_weight = 0.5;     ///< fraction of the tangential move taken per iteration, in [0, 1]
  /// Surface-diffusion time step (units of the umbrella operator), in [0, 0.5]. Off by default:
  /// reprojection along the gradient undoes the normal motion (measured: no effect on the
  /// result, docs/surface-smoothing.md).
  double normal_weight = 0.0;
  double interior_weight = 0.5;       ///< fraction of the move to the hexes' mass centre, in [0, 1]
  int interior_layers = 2;            ///< hex layers below the boundary whose vertices relax (≥ 0)
  int interior_sweeps = 2;            ///< interior sweeps after each boundary sweep (≥ 0)
  double min_hex_sj = 0.2;            ///< soft floor of the hexes' scaled Jacobian, in [0, 1] (see file comment)
  double min_quad_sj = 0.2;           ///< soft floor of the boundary quads' scaled Jacobian, in [0, 1]
  int max_halvings = 4;               ///< step-backs of a rejected move before dropping it (≥ 0)
  double crease_angle_degrees = 60;   ///< dihedral angle marking a crease, in (0, 180]; 180 = none
  /// A crease is a *feature*, held also by the max–min pass, when the isosurface's normal
  /// (−∇L) turns by more than this angle between the edge's ends, in [0, 180]: 0 = every
  /// crease, 180 = none. The relaxation holds every crease; folds of the quads over a smooth
  /// (if noisy) surface look like creases, and only the max–min pass can unfold them.
  double field_crease_angle_degrees = 30;
  double level_tolerance = 1e-7;      ///< projection target |L| ≤ this × the field's value range, in (0, 1e-6]
  double projection_reach = 1.0;      ///< largest projection distance, × the vertex's mean boundary edge length
  /// Farthest a boundary vertex may move from where it is once on the isosurface, × its mean
  /// boundary edge there, > 0: relaxation and max–min moves improve the quads around a vertex,
  /// they must not carry it along the surface (see within_travel() in vertex_moves.hpp).
  double max_travel = 1.0;
  double convergence = 1e-4;          ///< stop once no vertex moved more than this × the mean boundary edge length
  /// Also stop once the relaxation has stalled for this many iterations (0: never): the boundary
  /// quads below 0.2 reached no new low and their mean scaled Jacobian rose by less than
  /// `stall_gain` over them. (A few vertices keep oscillating, so on scans `convergence` is
  /// never met: on cthead at h 2 the count below 0.2 stayed at 1,470 from the 25th iteration
  /// to the 100th while the mean rose by 4.5e-4; with 20 the stage stops at the 80th. With 10
  /// it stopped at the 37th, but headsq at iso 1000, h 2.5 then ended with 2 hexes below 0.2.)
  int stall_iterations = 20;
  double stall_gain = 1e-4;
  /// Check the hexes as well as the boundary quads. Off when a boundary pillow follows: the
  /// pillow gives every boundary quad a new hex and the hexes below are re-shaped anyway,
  /// so only the surface's own quality matters, and the hexes' floors would block it. Interior
  /// moves check their hexes all the same (vertex_moves.hpp).
  bool guard_hexes = true;
  /// Passes of local max–min moves after the relaxation (0 = none): each boundary vertex of a
  /// quad below `worst_target` searches its tangent plane for the point on the isosurface that
  /// most raises the smallest scaled Jacobian of its quads (a quad facing inward counts as −2).
  /// This is what unfolds boundary quads; the relaxation alone leaves them.
  int worst_passes = 40;
  double worst_target = 0.5;          ///< quads below this are worked on, in [0, 1]
  double worst_radius = 0.5;          ///< first trial step, × the vertex's mean boundary edge, in (0, 2]
  int worst_levels = 6;               ///< step halvings of the search, in [1, 30]
  bool use_mesh_fixed = true;         ///< treat `mesh.fixed` as pinned
  std::vector<std::uint8_t> pinned;   ///< optional mask, one per vertex: 1 = pinned (e.g. on a volume-box face)
  /// Optional, one per vertex: −1, or the axis (0–2) of an axis-aligned plane through the
  /// vertex that it must stay in (box_face_axes(): a face of the domain box where the box cuts
  /// the solid). A vertex whose boundary quads all lie in that plane slides in the plane;
  /// one on the rim where the plane meets the isosurface slides along that curve. Pinned
  /// vertices stay pinned.
  std::vector<std::int8_t> planar;
};

/// Scaled-Jacobian figures of a mesh and its boundary.
struct SurfaceQuality {
  double quad_sj_min = 0;          ///< smallest boundary-quad scaled Jacobian
  double quad_sj_mean = 0;         ///< mean boundary-quad scaled Jacobian
  std::size_t quads_below = 0;     ///< boundary quads with scaled Jacobian < 0.2 (kQuestionableSJ)
  std::size_t num_quads = 0;       ///< boundary quads
  /// Smallest *fan margin* of a boundary vertex: how well one direction can point into all
  /// the quad corners around it (see docs/surface-smoothing.md). A boundary hex (or pillow
  /// hex) corner there cannot have a scaled Jacobian above it.
  double fan_margin_min = 0;
  std::size_t fans_below = 0;      ///< boundary vertices with fan margin < 0.2 (kQuestionableSJ)
  double hex_sj_min = 0;           ///< smallest hex scaled Jacobian (degenerate hexes excluded)
  std::size_t hexes_inverted = 0;  ///< hexes with scaled Jacobian < 0
  std::size_t hexes_degenerate = 0;///< hexes with Verdict's degenerate marker
};

/// What smooth_surface() did.
struct SurfaceSmoothingReport {
  SurfaceQuality before;           ///< the input
  SurfaceQuality projected;        ///< after projecting the boundary onto the isosurface (the guarantees' baseline)
  SurfaceQuality after;            ///< the result
  int iterations = 0;              ///< outer iterations run
  bool converged = false;          ///< stopped by `convergence` rather than by `iterations`
  bool stalled = false;            ///< stopped by `stall_iterations`
  double max_level = 0;            ///< max |L| over the boundary vertices that are not pinned, at the end
  double max_level_relative = 0;   ///< max_level / the field's value range
  std::size_t off_surface = 0;     ///< unpinned boundary vertices with |L| > 1e-6 × value range at the end
  double max_displacement = 0;     ///< largest distance any vertex moved, start to end
  std::size_t boundary_vertices = 0;
  std::size_t pinned_vertices = 0;     ///< pinned by mesh.fixed or options.pinned (all vertices)
  std::size_t outside_grid = 0;        ///< boundary vertices pinned for lying over a cell outside the field's grid
  std::size_t crease_vertices = 0;     ///< unpinned boundary vertices held on a crease
  std::size_t interior_vertices = 0;   ///< interior vertices allowed to relax
  std::size_t colours = 0;             ///< colour classes used (boundary + interior)
  std::size_t moves_halved = 0;        ///< accepted moves that needed at least one step-back
  std::size_t moves_dropped = 0;       ///< moves rejected after all step-backs
  int worst_passes = 0;                ///< max–min passes run
  std::size_t worst_moves = 0;         ///< max–min moves taken
};

/// Smooths the boundary of `mesh` on the isosurface of `field` and relaxes the hexes below
/// it (see the file comment). Throws isohex::Error for an empty mesh, a vertex id out of
/// range, non-finite coordinates, masks of the wrong size, options out of range, a field
/// whose grid is not 3-D (fewer than 2 points on an axis), whose value count does not match
/// its dimensions or whose values are all equal. Boundary vertices more than one grid cell
/// outside the field's grid box are pinned (SurfaceSmoothingReport::outside_grid).
SurfaceSmoothingReport smooth_surface(HexMesh& mesh, const IsoField& field,
                                      const SurfaceSmoothingOptions& options = {});

/// For each boundary vertex of `mesh` that lies on exactly one face of the box [lo, hi]
/// (within `relative_tolerance` × the box diagonal), that face's axis (0–2); −1 for every
/// other vertex, those on the box's edges and corners included. Feeds
/// SurfaceSmoothingOptions::planar.
std::vector<std::int8_t> box_face_axes(const HexMesh& mesh, const Vec3& lo, const Vec3& hi,
                                       double relative_tolerance = 1e-9);

/// The scaled-Jacobian figures smooth_surface() reports, for any mesh.
SurfaceQuality surface_quality(const HexMesh& mesh);

/// Boundary vertices lying on a face of `volume`'s grid box (within `relative_tolerance` ×
/// the box diagonal), as a mask for SurfaceSmoothingOptions::pinned: where a mesh is cut
/// by the box, its boundary there is not on the isosurface and must stay put.
std::vector<std::uint8_t> volume_box_vertices(const HexMesh& mesh, const Volume& volume,
                                              double relative_tolerance = 1e-9);

}  // namespace isohex
