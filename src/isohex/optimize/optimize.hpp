#pragma once
/// \file optimize.hpp
/// \brief Moving interior vertices of a hex mesh: untangling, mean-ratio shape optimisation
/// and a worst-element pass, with chosen vertices held fixed.
///
/// All three stages are local: one vertex moves at a time, everything else frozen, and a move
/// is kept only if it lowers that vertex's share of the objective (or, in the worst-element
/// pass, raises the lowest scaled Jacobian around it). Vertices are graph-coloured so that no
/// two vertices of a colour share a hex; colours are visited in order and the vertices of one
/// colour in parallel (oneTBB). A vertex's move reads only vertices of other colours, so the
/// result is bit-identical for any thread count.
///
/// Each hex contributes 9 frames (3×3 matrices A linear in its 8 corners): the 8 corner frames
/// of Verdict's scaled Jacobian (kCornerNeighbors) and the centre frame (principal axes / 4),
/// all measured in units of the hex's mean edge length at the start of a stage, so that a
/// unit cube has A = I in every frame. A hex is valid (scaled Jacobian > 0) when all 9
/// determinants are positive.
///
/// - untangle(): Garanzha et al. 2021 ("Foldover-free maps in 50 lines of code")-style
///   regularised energy per frame, f = |A|²/(3 χ^{2/3}) + λ (D² + 1)/χ with
///   χ(D, ε) = (D + sqrt(ε² + D²))/2, minimised by per-vertex Newton steps with backtracking,
///   ε lowered between sweeps. It continues past "no inverted element" until the minimum
///   scaled Jacobian reaches a margin, because a barrier objective must never be handed a mesh
///   that is invalid by rounding (the failure observed with Mesquite on pave1 and ECR bust).
///   Hexes that the fixed vertices make impossible are proven so first (find_infeasible(): an
///   inverted frame of fixed vertices, or an LP showing that a free vertex has no place) and
///   given up. Hexes that stay inverted while ε falls (no proof, e.g. several free vertices
///   squeezed between folded boundary sheets) are *stuck*: their ε is frozen so that their
///   frames cannot dominate the energy of the rest. When neither the inverted count nor the
///   smallest determinant improves for a number of iterations (a stall), max–min LP moves (each
///   vertex to the place that maximises its smallest frame determinant, keeping valid hexes
///   valid) try to open the knot, and if they gain nothing the untangler stops.
/// - optimize_shape(): Knupp's inverse mean ratio |A|²/(3 det(A)^{2/3}) summed over the 8
///   corner frames of each valid hex (ideal: the unit cube corner). A move must keep all 9
///   determinants of every incident hex positive, so no valid hex is ever inverted, and it
///   must lower the objective, so the objective never increases.
/// - improve_worst(): local max–min moves on the vertices of the worst hexes (an LP on the
///   linearised frame values of Verdict's scaled Jacobian), accepted only if the smallest of
///   the values the vertex changes (frames and ratio terms) rises, the certified minimum around
///   the vertex stays above WorstOptions::sj_floor (or does not fall), and the Bernstein bound
///   of the jacobian ratio stays above WorstOptions::ratio_floor (or does not fall).
///
/// Valid means valid inside: every stage treats a hex as valid only when it is certified so by
/// the Bernstein coefficients of det J (quality/jacobian_bounds.hpp), not by Verdict's nine
/// samples, and no accepted move takes a certified hex out of that set. The untangler counts a
/// hex that is not certified as inverted and adds interior frames (Gauss points, edge and face
/// midpoints) to its energy.
///
/// With a BoundarySurface (slide.hpp) in the options, its sliding boundary vertices move too:
/// tangential steps, put back on the input's boundary surface or on an IsoField's isosurface
/// (a step that cannot be put back on the isosurface is refused).

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/mesh/topology.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace isohex {

class BoundarySurface;  // optimize/slide.hpp

/// Which vertices the optimisers hold fixed.
enum class FixedVertices {
  boundary,  ///< the vertices of boundary quads (default: the shape of the domain is kept)
  file,      ///< the mesh's own `fixed` flags (e.g. a VTK `fixed` point array)
  none,      ///< every vertex may move
};

/// The fixed-vertex mask (1 = fixed) for a choice; `file` with a mesh without flags fixes none.
std::vector<std::uint8_t> fixed_mask(const HexMesh& mesh, FixedVertices which);

/// A colouring of the free vertices: vertices of one colour share no hex.
struct VertexColoring {
  std::vector<std::vector<Index>> colors;  ///< free vertex ids per colour, ascending
};
/// Greedy colouring in vertex order (deterministic). Fixed vertices are left out. `inc`:
/// vertex_hexes(mesh) if the caller has it (null: built here).
VertexColoring color_vertices(const HexMesh& mesh, const std::vector<std::uint8_t>& fixed,
                              const Incidence* inc = nullptr);

/// The places of the vertices an optimisation may move (those not flagged in `fixed`), to go
/// back to: a copy of those alone, or of every point where nearly all are free (an id and a
/// place cost more than a place). A band round holds all but a few thousand of cthead h 2's
/// 634,000 vertices, and whole copies of the points were 15 MB each.
class PointSnapshot {
 public:
  PointSnapshot(const HexMesh& mesh, const std::vector<std::uint8_t>& fixed);
  void take(const HexMesh& mesh);     ///< the places now
  void restore(HexMesh& mesh) const;  ///< back to the places taken
  /// How many vertices' places it holds (at least the free ones).
  std::size_t held() const { return at_.size(); }

 private:
  bool whole_ = false;      ///< every point is held (at_[v] is vertex v's place)
  std::vector<Index> ids_;  ///< else the held vertices, ascending (at_[i] is ids_[i]'s place)
  std::vector<Vec3> at_;
};

/// One line of progress.
struct IterationReport {
  std::string stage;        ///< "untangle", "lp" (a max–min LP rescue; objective = moves), "shape" or "worst"
  int iteration = 0;
  double objective = 0;     ///< stage objective (shape: mean inverse mean ratio over corners)
  double min_sj = 0;        ///< minimum scaled Jacobian (Verdict) of the mesh
  std::size_t inverted = 0; ///< hexes with scaled Jacobian <= 0
};
using ProgressCallback = std::function<void(const IterationReport&)>;

/// 1 for every vertex outside `rings` hex-rings of the hexes whose scaled Jacobian `sj` is
/// below `margin` (or degenerate; hexes flagged in `skip` left out), 0 within: the vertices a
/// local pass holds (the untangler; `isohex mesh`'s band rounds).
std::vector<std::uint8_t> frozen_outside(const HexMesh& mesh, const Incidence& inc, const std::vector<double>& sj,
                                         double margin, int rings, const std::vector<std::uint8_t>* skip = nullptr);

/// Options of the untangler.
struct UntangleOptions {
  double margin = 0.05;   ///< stop once the minimum scaled Jacobian reaches this
  int max_iter = 200;     ///< outer iterations (ε updates)
  int sweeps = 1;         ///< Gauss–Seidel sweeps per outer iteration (each vertex: two Newton steps)
  double lambda = 0.5;    ///< weight of the volume term (D² + 1)/χ
  int rings = 3;          ///< move only vertices within this many hex-rings of hexes below the margin
  /// Culling: after the first iteration, move only the vertices of the hexes around a vertex
  /// that moved more than this fraction of its mean edge in the iteration before, or around a
  /// hex below the margin that is not stuck (0: every vertex within `rings`). The vertices
  /// around stuck hexes settle after a few iterations and were swept again for the rest.
  double cull = 0.01;
  /// Lowest relative decrease σ assumed by the ε schedule (ε's worst-frame χ shrinks by 1 − σ
  /// per iteration).
  double min_decrease = 0.5;
  /// A hex inverted whose smallest frame determinant has not risen by 1e-3 for this many
  /// iterations is *stuck*: its ε is frozen and it leaves the ε schedule (released if it
  /// becomes valid).
  int stuck_after = 5;
  /// ... counted only while ε is below the inverted depth |D| or below this.
  double stuck_eps = 1e-3;
  /// A hex still inverted when ε has fallen below this fraction of its depth |D| is stuck at once
  /// (the energy has pressed on it ~1/stuck_depth² times harder than at ε = |D| in vain).
  double stuck_depth = 0.01;
  /// Stop (after `rescues` max–min LP rescues that gained something) when neither the number of
  /// inverted hexes nor the smallest determinant of the hexes not stuck improved for this many
  /// iterations.
  int stall = 10;
  double stall_fraction = 0.05;  ///< ... (fewer inverted: by this fraction of them, at least 1)
  int rescues = 5;
  const BoundarySurface* surface = nullptr;  ///< boundary vertices that slide on it (null: none)
  /// vertex_hexes(mesh) if the caller has it, to share (null: built here).
  const Incidence* incidence = nullptr;
  ProgressCallback progress;
};

/// A set of hexes that cannot all be valid with the given fixed vertices, and why.
struct InfeasibleSet {
  enum class Kind {
    fixed_frame,  ///< a frame (a corner, or the centre of an all-fixed hex) made of fixed vertices only is
                  ///< inverted, flat, or has an edge Verdict calls degenerate (collapsed)
    vertex_cone,  ///< the frames in which `vertex` is the only free vertex have no common positive point (an LP proves it)
  };
  Kind kind = Kind::fixed_frame;
  Index vertex = -1;          ///< fixed_frame: the frame's corner vertex; vertex_cone: the free vertex with no valid place
  std::vector<Index> hexes;   ///< at least one of these hexes stays invalid whatever the free vertices do (ascending)
};
/// "fixed_frame" / "vertex_cone".
const char* to_string(InfeasibleSet::Kind kind);

/// Proofs that some hexes cannot all be made valid with `fixed` held: inverted frames of fixed
/// vertices only, and free vertices whose frames with otherwise fixed vertices leave no place
/// (the maximal inscribed ball of their half-spaces, an LP, has radius below 1e-9 edge lengths).
/// Deterministic, ordered by kind, then vertex.
std::vector<InfeasibleSet> find_infeasible(const HexMesh& mesh, const std::vector<std::uint8_t>& fixed);

/// A proof that some hexes cannot all reach a scaled Jacobian level with the fixed vertices held.
struct QualityBound {
  enum class Kind {
    fixed_frame,     ///< a frame (a corner, or the centre of an all-fixed hex) of fixed vertices only: its value
    edge_direction,  ///< the corner frames at fixed `vertex` whose only free vertex is `free`: each is
                     ///< n_i · u with u the unit direction of the edge to `free` and n_i the cross product of the
                     ///< frame's two fixed unit edges, so the best their smallest can be is the distance from 0 to
                     ///< the convex hull of the n_i (then u points at the hull's nearest point)
  };
  Kind kind = Kind::fixed_frame;
  Index vertex = -1;         ///< the frame's corner (fixed); -1 for a centre frame
  Index free = -1;           ///< edge_direction: the free end of the edge
  double bound = 0;          ///< the largest value the smallest of these frames can take (<= 0: none valid)
  std::vector<Index> hexes;  ///< at least one of these hexes stays at or below `bound` (ascending)
};
/// "fixed_frame" / "edge_direction".
const char* to_string(QualityBound::Kind kind);

/// Proofs that some hexes cannot all reach a scaled Jacobian of `level` with `fixed` held, each
/// with the best its hexes' smallest value can be (bound < level): frames of fixed vertices only,
/// and fixed corners whose frames share one free edge (a boundary vertex of valence 3 whose
/// boundary quads meet at a sharp angle: ECR block_in, 0.197 at best). A relaxation: the frames
/// of a set are judged alone, so a set whose bound is above `level` may still be impossible.
/// Deterministic, ordered by kind, then vertex, then free vertex.
std::vector<QualityBound> find_quality_bounds(const HexMesh& mesh, const std::vector<std::uint8_t>& fixed,
                                              double level = 0.2);

/// What the untangler did.
struct UntangleResult {
  int iterations = 0;
  double min_sj = 0;               ///< after, over the hexes not given up
  std::size_t inverted = 0;        ///< hexes with scaled Jacobian <= 0 after (all of them, given up or not)
  bool reached_margin = false;     ///< every hex not given up reached the margin
  std::size_t lp_moves = 0;        ///< max–min LP moves taken when the barrier stalled
  /// Vertices swept, summed over the iterations (each sweep up to two Newton steps per vertex):
  /// the work, which UntangleOptions::cull lowers.
  std::size_t vertex_sweeps = 0;
  /// find_infeasible()'s proofs, and for each one hex that the untangler gives up (leaves out
  /// of its energy so that the rest can be untangled; chosen per proof as the lowest scaled
  /// Jacobian among its hexes, then lowest id, until the rest of the proof's frames admit a
  /// valid place). Only these hexes may stay inverted because of the fixed vertices.
  std::vector<InfeasibleSet> infeasible;
  std::vector<Index> given_up;     ///< ascending
  /// Hexes (not given up) that stopped improving while inverted, had their ε frozen, and are
  /// still inverted at the end (ascending).
  std::vector<Index> stuck;
  /// Why it stopped: "margin" (reached), "stall" (no progress for UntangleOptions::stall
  /// iterations and no LP rescue left that gains), or "max_iter".
  std::string stop;
  bool stalled = false;            ///< stop == "stall"
};

/// Untangles `mesh` in place, vertices with fixed[v] != 0 untouched, every hex except the
/// given-up ones (see UntangleResult) towards the margin. If the margin is not reached, the
/// mesh is left in the best state seen (fewest inverted hexes not given up, then highest
/// minimum scaled Jacobian among them), never worse than the input by that order.
UntangleResult untangle(HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const UntangleOptions& options = {});

/// Options of the shape optimiser.
struct ShapeOptions {
  int max_iter = 100;        ///< Gauss–Seidel sweeps
  double tol = 5e-4;         ///< stop when a sweep lowers the objective by less than tol (relative) ...
  double min_sj_gain = 1e-3; ///< ... and raises the smallest certified scaled Jacobian by less than this
  double grad_tol = 1e-8;    ///< ... or when the largest vertex gradient (× edge length) is below this
  /// Culling: a sweep moves only the vertices of the hexes around a vertex that moved more
  /// than this fraction of its mean edge length in the sweep before (0: every vertex, every
  /// sweep). cthead h 3: sweeps 26.3 -> 9.8 s, mean scaled Jacobian 0.9000 -> 0.8997.
  double cull = 1e-2;
  const BoundarySurface* surface = nullptr;  ///< boundary vertices that slide on it (null: none)
  /// vertex_hexes(mesh) if the caller has it, to share (null: built here).
  const Incidence* incidence = nullptr;
  /// No step takes a hex's rank, the lower of its certified scaled Jacobian and twice its
  /// jacobian ratio bound, below the lower of its rank before the step and this (-inf: off).
  /// The mean objective otherwise trades minima for the mean: `isohex mesh`'s band rounds set
  /// 0.2 (kQuestionableSJ) so that they never undo what the worst pass before them reached.
  double rank_guard = -std::numeric_limits<double>::infinity();
  ProgressCallback progress;
};

/// What the shape optimiser did.
struct ShapeResult {
  int iterations = 0;
  double objective_before = 0, objective_after = 0;  ///< mean corner inverse mean ratio (1 = cubes)
  std::size_t frozen_hexes = 0;  ///< invalid hexes whose vertices were held (the barrier needs valid hexes)
  std::size_t culled = 0;        ///< free vertices held at the end by ShapeOptions::cull
  std::vector<double> history;   ///< objective after each sweep
};

/// The shape objective: Σ over valid hexes and their 8 corners of |A|²/(3 det(A)^{2/3}), divided
/// by the number of terms (1 for a mesh of cubes). Invalid hexes are left out.
double shape_objective(const HexMesh& mesh);

/// Lowers the inverse mean ratio in place; never inverts a valid hex, never raises the objective.
ShapeResult optimize_shape(HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const ShapeOptions& options = {});

/// Options of the worst-element pass.
struct WorstOptions {
  double below = 1.5;     ///< work on the vertices of hexes with scaled Jacobian below this ...
  std::size_t count = 100;  ///< ... at most this many of the worst,
  double raise_below = 0.3; ///< ... and on those of every hex below this (the questionable ones and a margin)
  int passes = 30;
  /// ... stopping early when the last `stall_passes` passes together raised the lowest rank by
  /// less than `stall_gain` and, while hexes are below 0.2 by rank, lowered their deficit (the
  /// sum of 0.2 - rank over them) by less than `stall_fraction` of it, or else raised the mean
  /// of the `count` lowest ranks by less than `stall_gain` (0: no such stop).
  int stall_passes = 10;
  double stall_gain = 1e-3;
  double stall_fraction = 0.01;
  /// The same test over this many passes for the single passes that follow a round of joint
  /// moves or a walk: those passes resume from a stall, and what the joint move opened up they
  /// take in the first two or three (cthead h 2's release round: 97 -> 59 passes, the same
  /// minimum 0.2011; h 4: 92 -> 65, the same 0.2009).
  int resume_stall_passes = 3;
  /// A move of a vertex: the max–min LP step within a box of half-side `step` × its mean edge
  /// length, halved up to `trials` times until the true values gain, the model rebuilt up to
  /// `models` times at the new place.
  double step = 0.25;
  int trials = 10;
  int models = 4;
  double target = 0.6;  ///< a vertex whose frame values are all at least this is not moved
  /// No move may make an edge shorter than this fraction of its length when the pass began.
  double min_edge_shrink = 0.5;
  /// ... nor raise the edge ratio (longest edge over shortest) of a hex around the vertex above
  /// the higher of its value before and this: the trade of sj_floor shortened pillow edges
  /// (headsq's largest edge ratio went from 16 to 34 without it).
  double max_edge_ratio = 20;
  /// ... or above the higher of its value before and this where a hex around the vertex has a
  /// ratio bound below 0.1 (the floor is a target, an edge ratio of 20 an aim: cthead at h 3
  /// kept 4 ratios below 0.1 with the cap of 20 everywhere).
  double poor_ratio_edge_limit = 100;
  /// No move may lower the smallest jacobian_ratio_bound() of the hexes around the vertex
  /// below the lower of its value before and this: the nine samples of the scaled Jacobian
  /// are not bought with a distorted interior.
  double ratio_floor = 0.2;
  /// With ratio_terms, a move may lower the smallest scaled Jacobian around the vertex (to raise
  /// a ratio term, the model's smallest value rising), but not below the higher of this and the
  /// mesh minimum: a pillow hex at ratio 0.093 beside a hex at 0.277 (headsq) is raised to
  /// 0.10 by taking the other to 0.205. Without ratio_terms the local minimum never falls.
  double sj_floor = 0.2;
  /// The max–min moves also raise the Bernstein coefficients of det J over each hex's largest
  /// (a lower bound of its jacobian ratio, weighted 2: a ratio of 0.1 counts as a scaled
  /// Jacobian of 0.2), and the worst hexes are chosen by the lower of the two. Where a ratio
  /// term is the smallest and cannot rise, a second phase raises the scaled-Jacobian frames
  /// alone with the ratio terms held at their smallest (LP constraints).
  bool ratio_terms = true;
  /// After the single moves: up to this many rounds of joint moves (0: none), each followed by
  /// up to 10 more single passes (stopping at a stall over `resume_stall_passes`). A max–min ascent one vertex at a time stops where two
  /// vertices' terms tie and either moving alone lowers the other's (cthead's bone at iso 1200,
  /// h 5: four pillow hexes at ratios 0.05-0.06 through 100 passes). Each cluster of hexes
  /// still below 0.2 by the pass's rank (sharing vertices) has the free vertices of its hexes
  /// moved together, one LP over all their coordinates (opt::move_patch), or where that gains
  /// nothing those of its worst hex, under the same guards as a single move.
  int patch_rounds = 5;
  std::size_t patch_size = 48;  ///< ... at most this many vertices in one patch
  /// ... and a cluster whose tries all failed is not tried again in the next round while nothing
  /// they read has changed (WorstResult::patch_skipped; the same mesh either way)
  bool patch_memo = true;
  /// ... and only while at most this many hexes are below 0.2 by rank: more are not stalls of
  /// the single moves but a region no joint move repairs (headsq with its boundary fixed kept
  /// 746 through five rounds that cost 6 times the rest of the stage).
  std::size_t patch_max_poor = 100;
  /// Last, while at most patch_max_poor hexes are below 0.2 by rank: a random walk over the free
  /// vertices within `search_rings` vertex rings of each cluster still below (at most
  /// `search_vertices` of them), up to `search_trials` steps a cluster, each step taken when no
  /// hex around it falls below the region's minimum, under the single moves' guards. The
  /// max–min ascents stop at stationary points of the nonsmooth minimum that are not its maximum
  /// (cthead's bone at iso 1200, h 5: four pillow hexes at a ratio of 0.052 through every
  /// single and joint move); the walk crosses the level set of the minimum sideways. 0: off.
  std::size_t search_trials = 200000;
  int search_rings = 2;
  std::size_t search_vertices = 400;
  const BoundarySurface* surface = nullptr;  ///< boundary vertices that slide on it (null: none)
  /// vertex_hexes(mesh) if the caller has it, to share (null: built here).
  const Incidence* incidence = nullptr;
  ProgressCallback progress;
};

/// What the worst-element pass did.
struct WorstResult {
  int passes = 0;
  std::size_t moves = 0;
  std::size_t patch_moves = 0;  ///< joint moves of patches (WorstOptions::patch_rounds)
  /// clusters not tried again in a round: their tries had all failed, and nothing they read had
  /// changed since (the same mesh as trying them)
  std::size_t patch_skipped = 0;
  std::size_t searched = 0, search_gains = 0;  ///< clusters the random search ran on, and raised
  double min_sj_before = 0, min_sj_after = 0;
  /// Wall seconds of the single passes, the joint moves of patches and the random walks.
  double passes_seconds = 0, patch_seconds = 0, search_seconds = 0;
  /// With fixed vertices and hexes still below 0.2 at the end: find_quality_bounds() at 0.2, the
  /// sets of hexes that no placement of the free vertices lifts all to 0.2. A hex below 0.2 in
  /// none of them is the pass's own shortfall.
  std::vector<QualityBound> proven;
};

/// Raises the lowest scaled Jacobians in place; the mesh minimum never decreases. The single
/// passes move vertices worst first as one sequence, the moves of vertices that share no hex
/// in parallel: the sequence's result, bit for bit, for any thread count.
WorstResult improve_worst(HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const WorstOptions& options = {});

/// The whole sequence `isohex smooth` and `isohex mesh` run: untangle (optional), shape, worst
/// pass (optional), with one fixed-vertex mask. One function, so both commands behave the same.
/// The stages share one incidence (their options' `incidence`, else one built here).
struct OptimizeOptions {
  bool untangle = true;
  bool worst = true;
  UntangleOptions untangle_options;
  ShapeOptions shape_options;
  WorstOptions worst_options;
};
struct OptimizeResult {
  bool untangled = false;  ///< the untangler ran
  UntangleResult untangle;
  ShapeResult shape;
  bool worst_run = false;  ///< the worst-element pass ran
  WorstResult worst;
  double untangle_seconds = 0, shape_seconds = 0, worst_seconds = 0;
};
OptimizeResult optimize_mesh(HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const OptimizeOptions& options = {});

/// Options of reattach_released().
struct ReattachOptions {
  /// A vertex goes back onto its surface only if no hex around it ends with a rank (the lower
  /// of its certified scaled Jacobian and twice its jacobian ratio bound) below the lower of
  /// its rank now and max(floor, the mesh's lowest rank): the minimum and the count below 0.2
  /// cannot get worse.
  double floor = 0.3;
  int rounds = 3;  ///< passes over the loose vertices (a vertex put back frees its neighbours)
};
/// What reattach_released() did.
struct ReattachResult {
  std::size_t loose_before = 0;  ///< loose vertices before
  std::size_t reattached = 0;    ///< of them, back on their surface and sliding again
};
/// Puts the vertices that BoundarySurface::loosen() released back onto their surface
/// (BoundarySurface::snap()) where the hexes around them allow it (ReattachOptions::floor),
/// and makes them slide again: released for the optimiser's sake, they need not stay off the
/// surface once it is done. Sequential in vertex order: the same mesh for any thread count.
ReattachResult reattach_released(HexMesh& mesh, BoundarySurface& surface, const ReattachOptions& options = {});

}  // namespace isohex
