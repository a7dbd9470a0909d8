#pragma once
/// \file feasibility.hpp
/// \brief Internal to optimize/: the frame determinants around one vertex as affine functions
/// of its position, a small LP that maximises their minimum (a max–min move, after Freitag &
/// Plassmann's LP-based untangling of simplicial meshes), and infeasibility certificates.
///
/// With every other vertex held, det(A_t) of each frame is affine in the position of one
/// vertex (matrix determinant lemma), so "the best place for v" in the max–min sense, and
/// "is there any place for v at all", are linear programs in 4 unknowns (3 coordinates and
/// the bound s).

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"

#include <array>
#include <vector>

namespace isohex::opt {

/// One affine function d ↦ a·d + b of a displacement d.
struct Affine {
  Vec3 a = Vec3::Zero();
  double b = 0;
};

/// Solution of max s s.t. f_i(d) >= s·w_i for all i, |d_j| <= box.
struct MaxMin {
  Vec3 d = Vec3::Zero();
  double s = 0;
  bool ok = false;  ///< false only if the simplex failed (no constraints, or its limit of 8 pivots a row reached)
};

/// Maximises the smallest f_i(d)/w_i over the cube |d_j| <= box (w_i > 0). A dense simplex
/// with Bland's rule: exact arithmetic order, so the same bits on every run.
MaxMin max_min_affine(const std::vector<Affine>& f, const std::vector<double>& w, double box);

/// The same LP in n unknowns: max s s.t. Σ_j a[i n + j] d_j + b_i >= s·w_i, |d_j| <= box_j (the
/// joint move of several vertices). `d` has n entries when ok.
struct MaxMinN {
  std::vector<double> d;
  double s = 0;
  bool ok = false;
};
MaxMinN max_min_affine(int n, const std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& w,
                       const std::vector<double>& box);

/// d det(A + d cᵀ)/dd: the gradient of a frame's determinant when one of its corners moves by d
/// and c is that corner's coefficient in the frame (frame_coefficient()).
Vec3 det_gradient(const Mat3& A, const Vec3& c);

/// Verdict's scaled Jacobian of frame A (its determinant over the product of its column
/// lengths) as an affine function of the place of a corner whose coefficient in the frame is c
/// (the gradient left zero with `value_only`); −2 for a collapsed column, as Verdict's
/// degenerate hex, below everything.
Affine scaled_frame(const Mat3& A, const Vec3& c, bool value_only = false);
/// Verdict's value of frame t (frame()'s numbering: the 8 corners, then the centre) of hex p.
inline double scaled_frame_value(const std::array<Vec3, 8>& p, int t) {
  return scaled_frame(frame(p, t, 1.0), Vec3::Zero(), true).b;
}

/// The largest Bernstein coefficient of det J of hex p, or 0 when none is positive: the norm of
/// the worst pass's ratio terms while a vertex (or a patch) moves.
double bernstein_norm(const std::array<Vec3, 8>& p);

/// The worst pass's ratio terms of hex p: `weight` × det J's 27 Bernstein coefficients over
/// `norm` in `b`, and, where g is not null, their gradients in the place of each corner k with
/// corners[k] set in (*g)[k] (each lattice determinant is affine in one corner: matrix
/// determinant lemma; the coefficients are fixed combinations of them).
void ratio_coefficients(const std::array<Vec3, 8>& p, double weight, double norm, const std::array<bool, 8>& corners,
                        std::array<double, 27>& b, std::array<std::array<Vec3, 27>, 8>* g);

/// The normalised determinants of the frames that see vertex v (each incident hex, the corner
/// frames using v and the centre frame) as affine functions of v's displacement. With `fixed`,
/// keeps just the frames whose other vertices are all fixed: only v can change those. Hexes
/// with (*skip)[h] set are left out; `hex_of` (may be null) receives each frame's hex.
std::vector<Affine> vertex_frames(const HexMesh& mesh, const Incidence& inc, const std::vector<double>& inv_len, Index v,
                                  const std::vector<std::uint8_t>* fixed = nullptr,
                                  const std::vector<std::uint8_t>* skip = nullptr, std::vector<Index>* hex_of = nullptr);

/// One Gauss–Seidel round of max–min moves: each vertex with active[v] set goes to the place
/// within half an edge length that maximises the smallest normalised determinant of its
/// frames (hexes with (*skip)[h] left out), if that raises it and every hex around v that is
/// valid (all 9 determinants > kMinFeasibleDet) stays valid. Colours in order, a colour's
/// vertices in parallel (they share no hex): the same bits for any thread count. Returns the
/// number of moves.
std::size_t max_min_sweep(HexMesh& mesh, const VertexColoring& coloring, const Incidence& inc,
                          const std::vector<double>& inv_len, const std::vector<std::uint8_t>& active,
                          const std::vector<std::uint8_t>* skip);

/// The hexes the untangler leaves out (1) so that it can untangle the rest: for each proof,
/// the hex of a fixed_frame; for a vertex_cone, its hexes by rising scaled Jacobian (then id)
/// until the vertex's remaining frames with fixed vertices admit a valid place.
std::vector<std::uint8_t> give_up(const HexMesh& mesh, const std::vector<std::uint8_t>& fixed,
                                  const std::vector<InfeasibleSet>& sets);

/// The mean length of the edges at v (0 for an unused vertex).
double mean_edge_at(const HexMesh& mesh, const Incidence& inc, Index v);

}  // namespace isohex::opt
