#pragma once
/// \file local_energy.hpp
/// \brief Internal to optimize/: the 9 frames of a hex, the per-frame energies and their
/// derivatives, the energy of one vertex's neighbourhood, and one Newton move of a vertex.
///
/// Frame t of a hex is A_t = (1/L) Σ_k P_k c_{t,k}ᵀ with constant coefficient vectors c (so
/// Σ_k c_{t,k} = 0: translation invariant). Moving one vertex P_k by d changes A_t by the rank-1
/// term (1/L) d c_{t,k}ᵀ, hence det(A_t) is *affine* in d (matrix determinant lemma) and
/// |A_t|² quadratic: the derivatives below are exact and cheap.

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

namespace isohex::opt {

using Mat3 = Eigen::Matrix3d;

/// Frames 0..7 are the corner frames (Verdict's kCornerNeighbors), 8 the centre frame.
inline constexpr int kFrames = 9;
inline constexpr int kCentreFrame = 8;
/// Frames 9..34 are Jacobian matrices inside the element: at the 8 Gauss points (2×2×2, where
/// a solver evaluates det J), the 12 edge midpoints and the 6 face centres. With the corners
/// and the centre they sample det J on the whole 3×3×3 lattice its Bernstein coefficients are
/// made of. The untangler adds them for hexes that are not certified valid inside, so that its
/// energy sees a fold that the 9 frames miss.
inline constexpr int kAllFrames = 35;

/// Below this normalised determinant a frame counts as inverted in the feasibility tests of
/// the shape stage: a safety gap so that Verdict's own rounding can never see a negative sign.
inline constexpr double kMinFeasibleDet = 1e-10;

/// Which energy a stage minimises.
struct EnergyParams {
  bool untangle = false;  ///< true: regularised energy (all 9 frames); false: inverse mean ratio (8 corners)
  double eps = 0;         ///< untangle: the regularisation ε
  double lambda = 0;      ///< untangle: weight of the volume term
  /// Hexes left out of vertex energies (may be null): the untangler's given-up hexes.
  const std::vector<std::uint8_t>* skip = nullptr;
  /// Boundary vertices that slide (may be null): their steps are made tangential and put back
  /// on this surface.
  const BoundarySurface* surface = nullptr;
  /// untangle: per-hex floors of ε (may be null): hex h uses max(eps, (*hex_eps)[h]). The
  /// untangler freezes ε for hexes that have stopped improving, so that their frames (which
  /// would grow like 1/ε) cannot dominate the energy of the vertices they share with others.
  const std::vector<double>* hex_eps = nullptr;
  /// Hexes whose energy also counts the interior frames 9..34 (may be null: none). In the
  /// shape stage these frames only constrain (like the centre frame).
  const std::vector<std::uint8_t>* interior = nullptr;
  /// untangle: hexes whose energy also counts det J's Bernstein coefficients (may be null:
  /// none): the untangler's hexes that are not certified valid inside now. Their 27 lattice
  /// samples may all be positive while det J is negative between them (on a face, say): the
  /// coefficients bound det J from below, and all of them positive certifies the hex.
  const std::vector<std::uint8_t>* bernstein = nullptr;
  /// Whether hex h counts its Bernstein coefficients (untangle only).
  bool bernstein_of(Index h) const { return untangle && bernstein && (*bernstein)[static_cast<std::size_t>(h)]; }
  /// shape: each hex's jacobian_ratio_bound() where it stands (may be null: computed per move).
  /// newton_move() reads the floors of its line search from it and, moving, stores the values
  /// at the place it returns (which the caller then takes), so it stays exact through a
  /// sweep; unused with a rank guard or `skip`.
  std::vector<double>* hex_ratio = nullptr;
  /// The number of frames hex h contributes.
  int frames_of(Index h) const { return interior && (*interior)[static_cast<std::size_t>(h)] ? kAllFrames : kFrames; }
  /// shape: no step takes a hex's rank (hex_rank()) below the lower of its rank before the step
  /// and this (-inf: no such guard; ShapeOptions::rank_guard).
  double rank_guard = -std::numeric_limits<double>::infinity();
  /// ε of hex h under these parameters.
  double eps_of(Index h) const { return hex_eps ? std::max(eps, (*hex_eps)[static_cast<std::size_t>(h)]) : eps; }
};

/// The parameter point (u, v, w) of frame t.
Vec3 frame_point(int t);

/// The frames at the 27 points of the 3×3×3 lattice, in Bernstein order (index i + 3j + 9k for
/// the point (i/2, j/2, k/2)): the Jacobian matrices whose determinants give det J's Bernstein
/// coefficients (quality/jacobian_bounds.hpp).
const std::array<int, 27>& lattice_frames();

/// x^(−1/3) for x > 0, within 2 ulp for normal x: the exponent divided by 3 from the bits, then
/// four Newton steps y ← y (4 − x y³)/3, each squaring the relative error, without a
/// division. The energies' D^(−2/3), D^(−5/3) and D^(−8/3) are its powers: glibc's cbrt with
/// its frexp, ldexp and scalbn calls took 14 % of cthead h 4's CPU (perf), and three divisions
/// per frame followed it.
inline double inverse_cbrt(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const std::uint64_t exponent = (bits >> 52) & 0x7ff;
  if (exponent == 0 || exponent == 0x7ff || (bits >> 63)) return 1 / std::cbrt(x);  // 0, subnormal, inf, NaN, < 0
  // The exponent field of x^(−1/3) is about (4/3)·1023 − e/3: 1364 less a tuning of 0.06.
  bits = 0x553F0A3D70A3D70AULL - bits / 3;
  double y;
  std::memcpy(&y, &bits, sizeof y);
  for (int i = 0; i < 4; ++i) y = y * (4.0 - ((x * y) * y) * y) * (1.0 / 3.0);  // x·y first: y³ may overflow
  return y;
}

/// Σ_{t<8} of the shape term of corner frame t of p (scaled by inv_len), in t order: the first
/// eight terms of the shape objective's hex_energy(), the same bits, four frames at a time.
double corner_shape_energy(const std::array<Vec3, 8>& p, double inv_len);

/// Per-hex 1/L, L = mean edge length (fixed for the length of a stage).
std::vector<double> inverse_edge_lengths(const HexMesh& mesh);

/// Frame t >= kFrames (an interior one) of corners p, scaled by inv_len (frame()).
Mat3 interior_frame(const std::array<Vec3, 8>& p, int t, double inv_len);
/// Corners p relative to p[0], entry by entry: what the interior frames are made of.
using RelativeCorners = std::array<std::array<double, 3>, 8>;
RelativeCorners relative_corners(const std::array<Vec3, 8>& p);
/// All interior frames of a hex at once, A[t − kFrames] = interior_frame(d, t, inv_len) bit for
/// bit (four frames at a time); without `gauss`, those of the 3×3×3 lattice only (the 8 Gauss
/// points' A[0..7] left unset).
using InteriorFrames = std::array<Mat3, kAllFrames - kFrames>;
void interior_frames(const RelativeCorners& d, double inv_len, InteriorFrames& A, bool gauss = true);

/// Corner frame t < 8 of corners p, scaled by inv_len (frame()).
[[gnu::always_inline]] inline Mat3 corner_frame(const std::array<Vec3, 8>& p, int t, double inv_len) {
  Mat3 A;
  const auto& nb = kCornerNeighbors[static_cast<std::size_t>(t)];
  for (int j = 0; j < 3; ++j) A.col(j) = (p[nb[j]] - p[t]) * inv_len;
  return A;
}

/// Frame t of corners p (already the hex's corners), scaled by inv_len. Inline: out of line,
/// its result went through memory as scalar stores read back as vector loads, a stall at every
/// frame of the energies' innermost loops (a tenth of vertex_energy()'s samples on cthead h 2).
[[gnu::always_inline]] inline Mat3 frame(const std::array<Vec3, 8>& p, int t, double inv_len) {
  if (t < 8) return corner_frame(p, t, inv_len);
  Mat3 A;
  if (t == kCentreFrame) {
    A.col(0) = ((p[1] - p[0]) + (p[2] - p[3]) + (p[5] - p[4]) + (p[6] - p[7])) * (0.25 * inv_len);
    A.col(1) = ((p[3] - p[0]) + (p[2] - p[1]) + (p[7] - p[4]) + (p[6] - p[5])) * (0.25 * inv_len);
    A.col(2) = ((p[4] - p[0]) + (p[5] - p[1]) + (p[6] - p[2]) + (p[7] - p[3])) * (0.25 * inv_len);
  } else {
    A = interior_frame(p, t, inv_len);
  }
  return A;
}

/// The coefficient c_{t,k} of corner k in frame t (zero when frame t does not use corner k).
const Vec3& frame_coefficient(int t, int k);

/// The energy of one hex's first `frames` frames under `params` (+inf if infeasible for the
/// shape stage), the untangling energy with regularisation `eps` (params.eps when negative).
double hex_energy(const std::array<Vec3, 8>& p, double inv_len, const EnergyParams& params, double eps = -1,
                  int frames = kFrames);

/// The energy hex h (corners p) contributes under `params`: its frames_of(h) frames, and its
/// Bernstein coefficients where bernstein_of(h).
double hex_energy(const std::array<Vec3, 8>& p, Index h, double inv_len, const EnergyParams& params);

/// True when all 9 frames of the hex have determinant > kMinFeasibleDet and the hex is
/// certified valid inside with det J > kMinFeasibleDet · L³ everywhere (Bernstein bounds,
/// certified_valid()): the validity every stage keeps.
bool hex_feasible(const std::array<Vec3, 8>& p, double inv_len);

/// True when every hex around v (those flagged in `skip` left out) is certified valid inside
/// with v at x, as hex_feasible() asks: for a shape step whose energy is finite (so the frames v
/// changes are feasible) from a place where every hex around v is hex_feasible().
/// With `ratio_floor` (one value per hex around v, in incidence order), also that no hex's
/// jacobian_ratio_bound() falls below its floor; with `rank_floor` (the same), that no hex's
/// hex_rank() does. With `ratios` (no rank_floor, no skip), each hex's jacobian_ratio_bound()
/// with v at x, in the same order, complete when the answer is true.
bool stays_feasible(const HexMesh& mesh, const Incidence& inc, const std::vector<double>& inv_len, Index v,
                    const Vec3& x, const std::vector<std::uint8_t>* skip,
                    const std::vector<double>* ratio_floor = nullptr, const std::vector<double>* rank_floor = nullptr,
                    std::vector<double>* ratios = nullptr);

/// The ratio terms are weighted this against the scaled Jacobian's frame values: 2 puts a ratio
/// of 0.1 (poor, kPoorJacobianRatio) level with a scaled Jacobian of 0.2.
inline constexpr double kRatioWeight = 2;

/// The worst pass's rank of a hex: the lower of its certified scaled Jacobian (-2 for a
/// degenerate hex) and kRatioWeight times its jacobian ratio bound.
inline double hex_rank(const CertifiedQuality& c) {
  return std::min(is_degenerate(c.scaled_jacobian) ? -2.0 : c.scaled_jacobian, kRatioWeight * c.ratio_bound);
}

/// No shape step takes a hex's jacobian_ratio_bound() from this or above to below it (a ratio
/// of 0.1 is poor, kPoorJacobianRatio; the bound is at most the ratio).
inline constexpr double kShapeRatioFloor = 0.1;

/// Frames (or a vertex's energy terms) stored four to a block, field by field, for vector
/// arithmetic over four at a time (frame_batch.cpp; the lanes do a frame-by-frame loop's
/// operations in its order, so the same bits).
struct FrameBatch {
  enum Field : int {
    kA = 0,           ///< in: the frame A, column-major: A(r, c) at kA + r + 3c
    kC = 9,           ///< in: the vertex's coefficient c in it (3)
    kIl = 12,         ///< in: 1/L of its hex
    kSq = 13,         ///< in: |c|² (as Eigen's squaredNorm() gives it)
    kEps = 14,        ///< in: the untangler's ε of its hex
    kConstraint = 15, ///< in: 1 for the shape stage's centre and interior frames (validity only)
    kF = 16,          ///< out: F = |A|²
    kD = 17,          ///< out: D = det A
    kValue = 18,      ///< out: the term's energy (the shape term's for a constraint too)
    kGrad = 19,       ///< out: its gradient in the vertex's place (3)
    kIdentity = 22,   ///< out: its Hessian's multiple of the identity, fF·2·il²·|c|²
    kHessian = 25,    ///< out: the rest of its Hessian, lower triangle (0,0) (1,0) (2,0) (1,1) (2,1) (2,2)
    kGF = 31,         ///< out: ∇F (3)
    kGD = 34,         ///< out: ∇D (3)
    kCc = 37,         ///< out: il²·|c|², F's curvature along a step
    kFields = 38
  };
  static constexpr std::size_t kBlock = 4 * kFields;

  std::vector<double> data;
  std::size_t size = 0;

  void clear() { size = 0; }
  double& at(std::size_t i, int field) { return data[(i / 4) * kBlock + static_cast<std::size_t>(field) * 4 + i % 4]; }
  double at(std::size_t i, int field) const {
    return data[(i / 4) * kBlock + static_cast<std::size_t>(field) * 4 + i % 4];
  }
  /// A new slot at the end (its fields unset).
  std::size_t add() {
    if (size % 4 == 0 && data.size() < (size / 4 + 1) * kBlock) data.resize((size / 4 + 1) * kBlock);
    return size++;
  }
  /// Evaluates every frame's outputs from its inputs: the untangler's term (its ε, volume weight
  /// `lambda`) or the shape term.
  void compute(bool untangle, double lambda);
};

/// Up to 28 frames field by field (the 27 of the Bernstein lattice, a spare lane), and what
/// compute() makes of them four at a time: each frame's determinant (Eigen's determinant(), bit
/// for bit) and, with `gradients`, det_gradient(A, c) of its coefficient c.
struct LatticeFrames {
  static constexpr int kLanes = 28, kBlocks = 7;
  std::array<std::array<double, kLanes>, 9> a{};  ///< A(r, c) at a[r + 3c]
  std::array<std::array<double, kLanes>, 3> c{};
  std::array<double, kLanes> det{};
  std::array<std::array<double, kLanes>, 3> grad{};
  void set_frame(int n, const Mat3& A) {
    for (int e = 0; e < 9; ++e) a[static_cast<std::size_t>(e)][static_cast<std::size_t>(n)] = A.data()[e];
  }
  void compute(bool gradients);
};

/// The terms of a vertex's energy as functions of the vertex's displacement d from where they
/// were recorded: a frame changes by the rank-one il·d·cᵀ, so its F = |A|² is F0 + gF·d +
/// cc·|d|² and its D = det A is D0 + gD·d, exactly (a Bernstein coefficient is affine alike).
/// A line search's trial then costs a few products per term instead of rebuilding the frames
/// from the corners (the untangler's searches on cthead took 2.1 trials a move, some 15).
/// Each term is a FrameBatch slot (its kF, kD, kCc, kEps, kGF, kGD and kConstraint fields):
/// vertex_energy() hands its batch over whole where no Bernstein term comes between its frames.
struct TermModels {
  /// The untangler's terms (a Bernstein coefficient's is one with F0, gF and cc zero) or the
  /// shape stage's (inverse mean ratio, or a constraint: D > kMinFeasibleDet, no energy).
  bool untangle = false;
  FrameBatch terms;

  std::size_t size() const { return terms.size; }
  bool empty() const { return terms.size == 0; }
  void clear(bool untangle_terms) { terms.clear(), untangle = untangle_terms; }
  void push(double F0, double D0, double cc, double eps, const Vec3& gF, const Vec3& gD, bool constraint) {
    const std::size_t i = terms.add();
    terms.at(i, FrameBatch::kF) = F0, terms.at(i, FrameBatch::kD) = D0, terms.at(i, FrameBatch::kCc) = cc;
    terms.at(i, FrameBatch::kEps) = eps, terms.at(i, FrameBatch::kConstraint) = constraint ? 1.0 : 0.0;
    for (int j = 0; j < 3; ++j) terms.at(i, FrameBatch::kGF + j) = gF[j], terms.at(i, FrameBatch::kGD + j) = gD[j];
  }
  /// Makes the last block's unused lanes a unit frame's (model_energy() evaluates whole blocks).
  void seal();
};
/// The energy of the recorded terms at displacement d: what vertex_energy() gives at x + d up
/// to rounding (+inf where a barrier term's D is at most kMinFeasibleDet), summed in term order.
double model_energy(const TermModels& model, const Vec3& d, double lambda);

/// The energy of the hexes around vertex v with v placed at x; with g and H, also its gradient
/// and Hessian with respect to x (the Hessian of the regularised energy may be indefinite).
/// +inf if the shape stage would make a hex infeasible. With `model` (and g), each term is also
/// recorded as a function of v's displacement from x, for model_energy().
double vertex_energy(const HexMesh& mesh, const Incidence& inc, const std::vector<double>& inv_len, Index v,
                     const Vec3& x, const EnergyParams& params, Vec3* g = nullptr, Mat3* H = nullptr,
                     TermModels* model = nullptr);

/// One Newton step of vertex v with a backtracking (Armijo) line search; returns the new
/// position (the old one if no step lowered the energy) and the scaled gradient norm |g|·L.
struct Move {
  Vec3 x;
  double grad = 0;
  bool moved = false;
  int trials = 0;  ///< the line search's energy evaluations
};
Move newton_move(const HexMesh& mesh, const Incidence& inc, const std::vector<double>& inv_len, Index v,
                 const EnergyParams& params);

/// Σ of hex energies, computed in parallel per hex and summed in hex order (deterministic).
/// `skip` (may be empty) leaves hexes out.
double total_energy(const HexMesh& mesh, const std::vector<double>& inv_len, const EnergyParams& params,
                    const std::vector<std::uint8_t>& skip = {});

/// Each hex's energy into e (sized to the hexes; 0 for hexes in `skip`), in parallel; with
/// `only`, just the hexes flagged there (the others keep their values). Summed in hex order
/// (energy_sum()) it is total_energy(), bit for bit.
void hex_energies(const HexMesh& mesh, const std::vector<double>& inv_len, const EnergyParams& params,
                  const std::vector<std::uint8_t>& skip, std::vector<double>& e,
                  const std::vector<std::uint8_t>* only = nullptr);
double energy_sum(const std::vector<double>& e);

/// Culling's record of sweeps (sweep()'s `record`): per vertex the largest, over the sweeps
/// since `moved` was cleared, of 0 (did not move), 1 (moved) and 2 (moved more than cull ×
/// scale[v] in one sweep). Written as the sweep moves each vertex: no copy of the points.
struct MoveRecord {
  const std::vector<double>* scale = nullptr;
  double cull = 0;
  std::vector<std::uint8_t> moved;
};
/// One Gauss–Seidel sweep: colours in order, the vertices of a colour in parallel, each taking
/// `steps` Newton moves. Vertices with frozen[v] set do not move (frozen may be empty); with
/// `record`, each move is recorded there. Returns the largest scaled gradient norm seen.
double sweep(HexMesh& mesh, const VertexColoring& coloring, const Incidence& inc, const std::vector<double>& inv_len,
             const EnergyParams& params, const std::vector<std::uint8_t>& frozen, int steps = 1,
             MoveRecord* record = nullptr);

/// Minimum certified scaled Jacobian (certified_scaled_jacobian(): Verdict's, 0 for a hex not
/// certified valid inside; degenerate counts as -1) and the number of hexes <= 0.
struct SJStats {
  double min = 0;
  std::size_t inverted = 0;
};
/// With `skip`, over the other hexes only.
SJStats sj_stats(const HexMesh& mesh, const std::vector<std::uint8_t>* skip = nullptr);
/// The same from certified scaled Jacobians already computed (one per hex).
SJStats sj_stats_of(const std::vector<double>& sj, const std::vector<std::uint8_t>* skip = nullptr);
/// certified_scaled_jacobian() of the hexes flagged in `only`, into sj (parallel).
void update_certified_sj(const HexMesh& mesh, const std::vector<std::uint8_t>& only, std::vector<double>& sj);
/// Culling, shared by the untangler and the shape stage: flags in `near` the vertices of the hexes
/// around each vertex that `record` saw move farther than its cull; with `changed`, the hexes
/// around every vertex that moved at all. Neither is cleared first.
void mark_far_moves(const HexMesh& mesh, const Incidence& inc, const MoveRecord& record, std::vector<std::uint8_t>& near,
                    std::vector<std::uint8_t>* changed = nullptr);

/// The caller's incidence if it gave one (it must be vertex_hexes(mesh)), else one built into
/// `own`: the stages of one optimisation share one instead of each holding its own (21 MB on
/// cthead h 2, two or three of them alive at once).
inline const Incidence& incidence_of(const HexMesh& mesh, const Incidence* given, Incidence& own) {
  if (given) return *given;
  own = vertex_hexes(mesh);
  return own;
}

/// The corners of hex h with its vertex v placed at x.
inline std::array<Vec3, 8> corners_with(const HexMesh& mesh, Index h, Index v, const Vec3& x) {
  std::array<Vec3, 8> p = mesh.corners(h);
  for (int k = 0; k < 8; ++k)
    if (mesh.hexes[h][k] == v) p[k] = x;
  return p;
}

/// The length scale of vertex v: the mean of its hexes' 1/inv_len (0 for an unused vertex).
inline double vertex_length(const Incidence& inc, const std::vector<double>& inv_len, Index v) {
  double len = 0;
  for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) len += 1 / inv_len[inc.ids[i]];
  return inc.count(v) > 0 ? len / static_cast<double>(inc.count(v)) : 0.0;
}

}  // namespace isohex::opt
