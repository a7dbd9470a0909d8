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

#include <array>
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
  bool guard_hexes = true;  ///< false: boundary moves check only the boundary quads (a pillow follows); interior moves always check their hexes
  /// Per vertex (or empty): −1; an axis a (0–2): the vertex slides in the plane x_a = const
  /// through it (a domain-box face) instead of on the isosurface; a + 3: it slides along the
  /// rim where that plane meets the isosurface.
  const std::vector<std::int8_t>* planar = nullptr;
  /// Per vertex (or empty): where its smoothing moves started and how far from there a move
  /// may take it (within_travel()).
  const std::vector<Vec3>* anchor = nullptr;
  const std::vector<double>* travel = nullptr;
};

/// The axis of the plane `v` stays in, or −1.
inline int plane_axis(const MoveContext& ctx, Index v) {
  return ctx.planar && !ctx.planar->empty() ? (*ctx.planar)[static_cast<std::size_t>(v)] % 3 : -1;
}

/// True if `v` slides along the rim where its plane meets the isosurface.
inline bool on_rim(const MoveContext& ctx, Index v) {
  return ctx.planar && !ctx.planar->empty() && (*ctx.planar)[static_cast<std::size_t>(v)] >= 3;
}

/// True if `v` slides in a box face (off the isosurface), not on the isosurface or its rim.
inline bool in_box_face(const MoveContext& ctx, Index v) { return plane_axis(ctx, v) >= 0 && !on_rim(ctx, v); }

/// Mean length of the boundary edges at `v` (0 for none).
double mean_boundary_edge(const MoveContext& ctx, Index v);

/// True if `y` is within `travel[v]` of `anchor[v]` (always, without them). Smoothing moves
/// equalise quads, they do not transport vertices: unbounded, the max–min pass carried
/// vertices of cthead's one-cell-thick table plate 178 mm along it in 40 passes (each step
/// improved its quads' scores), and the optimiser inherited hexes 60 mm long.
bool within_travel(const MoveContext& ctx, Index v, const Vec3& y);

/// Unit normal of the boundary at `v` from its quads (the sum of their area vectors).
Vec3 quads_normal(const MoveContext& ctx, Index v);

/// Puts `y`, a trial position of `v`, back on `v`'s surface within `reach`: its plane, the
/// isosurface (IsoField::project), or the rim curve where both meet (Newton steps in the
/// plane). True when it got there.
bool constrain(const MoveContext& ctx, Index v, Vec3& y, double reach);

/// Outward unit normal of the isosurface at boundary vertex `v` (−∇L normalised; the
/// boundary quads' mean normal where the gradient vanishes); for a planar vertex, the
/// plane's normal on the side its quads face.
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

/// Value oriented_quad_sj() gives a quad that has turned over.
inline constexpr double kFlippedQuad = -2.0;

/// Verdict's quad scaled Jacobian of `c`, or kFlippedQuad when the quad's centre normal
/// points against `reference` (a nonzero vector; zero = no check). Verdict's value is blind
/// to orientation: a quad folded over onto its neighbour can score 1.
double oriented_quad_sj(const std::array<Vec3, 4>& c, const Vec3& reference);

/// One local max–min move of boundary vertex `v` on its surface (worst_moves.cpp): a compass
/// search in the tangent plane (normal outward_normal()), 8 directions at steps of `radius`
/// × the vertex's mean boundary edge, halved up to `levels` times; each trial point is put
/// back on the surface by constrain(). Scores a trial by the scaled Jacobians of the boundary
/// quads around `v` and the fan_margin() of `v` and of its boundary neighbours, compared
/// leximin (the smallest first, then the next, ...); a quad that would turn over from where it
/// is now scores kFlippedQuad, and so does one with a nonzero `turned[q]` (one that has turned
/// over: turned_over_quads()) until it faces that reference. Takes the best trial at the
/// coarsest step that improves the score, so the smallest of those values never decreases.
/// Values above `cap` count as `cap`: good enough, and free to trade for the worse ones.
/// With `guard_hexes` the hexes around `v` must keep their floors as in
/// move_is_acceptable(). Returns dropped when no trial improves.
MoveOutcome raise_worst_quad(const MoveContext& ctx, Index v, double radius, int levels,
                             const std::vector<Vec3>& turned, double cap);

/// How well one direction can point out of every quad corner at boundary vertex `b` (with
/// vertex `v` moved to `y`): the largest, over unit directions d, of the smallest c·d over the
/// boundary quads at `b`, c being the corner's two edges' cross product over their lengths
/// (outward; its length is the sine of the corner angle, so a flat regular fan of 4 scores
/// 1). A pillow hex on each of those quads has its edge at `b` along −d: a fan with no
/// positive margin leaves one of them inverted whatever the optimiser does. Approximated by
/// the best of the corners' own directions, their pairwise bisectors and their sum.
double fan_margin(const MoveContext& ctx, Index b, Index v, const Vec3& y);
/// The same on any mesh and its graph.
double fan_margin(const HexMesh& mesh, const SurfaceGraph& graph, Index b, Index v, const Vec3& y);

/// The outward_normal() of each boundary vertex on the isosurface (`on_isosurface`), zero for
/// the others, kept through moves: update_normals() recomputes those flagged in `stale` (and
/// clears the flags); after a move of v, flag the vertices of its quads (a box-face vertex's
/// normal comes from its quads). The field's gradient at every boundary vertex, in each of the
/// worst-quad passes, was most of their sampling.
void update_normals(const MoveContext& ctx, const std::vector<std::uint8_t>& on_isosurface,
                    std::vector<std::uint8_t>& stale, std::vector<Vec3>& normal);

/// Per boundary quad, zero, or for a quad that faces inward an outward reference direction:
/// a quad faces inward when its normal points against both the isosurface's outward normals
/// at its corners that lie on the isosurface (`normal`: update_normals()) and the direction
/// from the opposite face of its hex to it. Needing both keeps noisy gradients on thin
/// features, and inverted hexes, from calling a quad turned over on their own. Into `turned`.
void turned_over_quads(const MoveContext& ctx, const std::vector<Vec3>& normal, std::vector<Vec3>& turned);

}  // namespace isohex::surface_detail
