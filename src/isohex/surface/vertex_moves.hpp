#pragma once
/// \file vertex_moves.hpp
/// \brief Internal to smooth_surface(): the move each vertex wants (surface diffusion and
/// tangential relaxation on the boundary, mass-centre relaxation inside) and the guarded
/// commit that steps a move back until no neighbouring element falls below its floor.
///
/// Every function here reads the vertex, the vertices sharing a hex with it and per-vertex
/// arrays, and writes only the vertex itself: safe to call in parallel for the vertices of
/// one colour class (no two share a hex).

#include "isohex/contour/iso_field.hpp"
#include "isohex/surface/surface_graph.hpp"

#include <cstdint>
#include <vector>

namespace isohex::surface_detail {

/// What a guarded move did.
enum class MoveOutcome : std::uint8_t {
  none,      ///< nothing to do (no step, already on the isosurface)
  accepted,  ///< the full step was taken
  halved,    ///< a stepped-back move (or only the projection) was taken
  dropped,   ///< every try was rejected; the vertex stayed
};

/// Shared state of one smoothing run.
struct MoveContext {
  HexMesh& mesh;
  const SurfaceGraph& graph;
  const IsoField& field;
  double hex_floor;        ///< soft floor of hexes (relaxation moves)
  double quad_floor;       ///< soft floor of boundary quads (relaxation moves)
  double quad_hard_floor;  ///< hard floor of boundary quads (the hexes' is 0)
  int max_halvings;
  double level_tolerance;  ///< absolute |L| a projection aims for
  double projection_reach; ///< × the mean boundary edge length at the vertex
  bool guard_hexes = true;  ///< false: only the boundary quads are checked (a pillow follows)
};

/// Outward unit normal of the isosurface at boundary vertex `v` (−∇L normalised; the
/// boundary quads' mean normal where the gradient vanishes).
Vec3 outward_normal(const MoveContext& ctx, Index v);

/// c_v − x_v, with c_v the area-weighted centroid of the boundary quads around `v`: the
/// umbrella Laplacian whose normal part is the discrete mean curvature the flow uses.
Vec3 quad_umbrella(const MoveContext& ctx, Index v);

/// The boundary step of `v`: `tangential_weight` × the tangential part of its umbrella,
/// minus `normal_weight` × (mean of `curvature` over its boundary neighbours − its own) along
/// the normal: one explicit step of surface diffusion, x_t = −Δ_B H n.
Vec3 boundary_step(const MoveContext& ctx, Index v, const std::vector<double>& curvature,
                   double tangential_weight, double normal_weight);

/// `weight` × (mass centre of the hexes around `v` − x_v): hex centroids weighted by their
/// (positive part of) volume, i.e. the centroid of the union of the hexes.
Vec3 interior_step(const MoveContext& ctx, Index v, double weight);

/// How demanding a move's check is.
enum class Check : std::uint8_t {
  relax,    ///< a smoothing move: soft and hard floors
  project,  ///< getting onto the isosurface: hard floors only
};

/// True if an element going from scaled Jacobian `before` to `after` is allowed: it must not
/// cross the soft floor downward, nor the hard one (≤ soft); an element already below the
/// hard floor must not get worse; between the two floors it may move freely.
bool keeps_floors(double before, double after, double soft_floor, double hard_floor);

/// True if moving `v` to `y` keeps_floors() for every hex around it (soft floor hex_floor,
/// hard floor 0: no new inverted hex) and, for a boundary vertex, every boundary quad around
/// it (quad_floor, quad_hard_floor). Check::project uses the hard floors as the soft ones.
bool move_is_acceptable(const MoveContext& ctx, Index v, const Vec3& y, bool boundary, Check check);

/// Moves boundary vertex `v` by `step` and projects it onto the isosurface (Check::relax); on
/// rejection retries with the step halved, and last, if `v` is off the isosurface, with no
/// step (projection only, Check::project): reaching the isosurface outranks quality.
MoveOutcome move_boundary_vertex(const MoveContext& ctx, Index v, const Vec3& step);

/// Moves interior vertex `v` by `step`, halving the step on rejection.
MoveOutcome move_interior_vertex(const MoveContext& ctx, Index v, const Vec3& step);

}  // namespace isohex::surface_detail
