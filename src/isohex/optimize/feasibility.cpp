// Affine frame determinants around one vertex and the 4-unknown LP that maximises their minimum.
#include "isohex/optimize/feasibility.hpp"

#include "isohex/internal/multiversion.hpp"

#include "isohex/optimize/local_energy.hpp"
#include "isohex/quality/jacobian_bounds.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace isohex::opt {

namespace {

// One pivot's elimination in the dictionary (rows × cols, row-major): every row i but r loses
// k·R (k = its entry in column e, R = row r already divided by the pivot p), its column-e entry
// becomes -k/p, and its right-hand side q[i] - k·q[r], clamped at 0. The joint moves' tableaux
// (hundreds of rows, up to 145 columns) made this loop a quarter of cthead h 4's CPU.
[[gnu::always_inline]] inline void eliminate_body(double* M, double* q, int rows, int cols, int r, int e, double p) {
  const double* __restrict R = M + static_cast<std::size_t>(r) * cols;
  for (int i = 0; i < rows; ++i) {
    if (i == r) continue;
    double* __restrict Mi = M + static_cast<std::size_t>(i) * cols;  // never row r
    const double k = Mi[e];
    if (k == 0) continue;
    for (int j = 0; j < cols; ++j) Mi[j] -= k * R[j];
    Mi[e] = -k / p;
    q[i] = std::max(q[i] - k * q[r], 0.0);  // clamp rounding: the dictionary stays feasible
  }
}

// The same arithmetic compiled for wider vectors where the CPU has them (the library builds with
// -ffp-contract=off, so no version fuses a multiply and a subtraction): the same bits on every
// machine.
#if ISOHEX_HAVE_FMV
[[gnu::target("default")]] void eliminate(double* M, double* q, int rows, int cols, int r, int e, double p) {
  eliminate_body(M, q, rows, cols, r, e, p);
}
[[gnu::target("avx2")]] void eliminate(double* M, double* q, int rows, int cols, int r, int e, double p) {
  eliminate_body(M, q, rows, cols, r, e, p);
}
[[gnu::target("avx512f")]] void eliminate(double* M, double* q, int rows, int cols, int r, int e, double p) {
  eliminate_body(M, q, rows, cols, r, e, p);
}
#else
void eliminate(double* M, double* q, int rows, int cols, int r, int e, double p) {
  eliminate_body(M, q, rows, cols, r, e, p);
}
#endif

}  // namespace

MaxMinN max_min_affine(int n, const std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& w,
                       const std::vector<double>& box) {
  MaxMinN out;
  const int m = static_cast<int>(b.size());
  if (m == 0 || n <= 0) return out;
  for (double x : box)
    if (!(x > 0)) return out;
  const auto A = [&](int i, int j) { return a[static_cast<std::size_t>(i) * n + j]; };
  // Unknowns y = (u, σ) >= 0 with d_j = box_j (u_j − 1), u_j <= 2 (the box), and s = σ − S, S
  // chosen so that y = 0 is feasible: f_i(d) >= s·w_i  ⇔  −Σ box_j a_ij u_j + w_i σ <= b_i − Σ box_j a_ij + S w_i.
  // reach[i]: how far f_i can move over the box; U: an upper bound of s (see below).
  // Per-thread buffers, none zeroed that is written whole (the worst pass solves one LP per
  // trial box: their allocations and zeroing were a tenth of its instructions).
  thread_local std::vector<double> shift, reach, M, q, c;
  thread_local std::vector<int> kept, B, N;
  shift.resize(static_cast<std::size_t>(m)), reach.resize(static_cast<std::size_t>(m));
  double S = 0, U = std::numeric_limits<double>::infinity();
  for (int i = 0; i < m; ++i) {
    double sh = 0, re = 0;
    for (int j = 0; j < n; ++j) sh += box[j] * A(i, j), re += box[j] * std::abs(A(i, j));
    shift[i] = sh, reach[i] = re;
    S = std::max(S, (shift[i] - b[i]) / w[i]);
    U = std::min(U, (b[i] + reach[i]) / w[i]);
  }
  S += 1;
  // Rows that bind nowhere in the box are left out: f_i >= s·w_i holds wherever s is feasible
  // when f_i's least value over the box exceeds w_i·U, U = min_k (largest f_k over the box)/w_k
  // (an upper bound of s). Such a row's slack is positive at every vertex, so it never leaves
  // the basis and Bland's rule (indices kept in order) takes the same pivots on the rest, with
  // the same arithmetic: the same bits, on a third to a half of the rows (the worst pass's
  // ratio terms far above its minimum).
  kept.clear();
  for (int i = 0; i < m; ++i)
    if (!(b[i] - reach[i] > w[i] * U + 1e-9 * (1 + std::abs(w[i] * U)))) kept.push_back(i);
  const int mk = static_cast<int>(kept.size());
  const int rows = mk + n, cols = n + 1;
  // Dictionary form: x_B[i] = q[i] − Σ_j M[i][j] x_N[j], objective z = const + Σ_j c[j] x_N[j].
  M.resize(static_cast<std::size_t>(rows) * cols), q.resize(static_cast<std::size_t>(rows));
  c.assign(static_cast<std::size_t>(cols), 0.0);
  B.resize(static_cast<std::size_t>(rows)), N.resize(static_cast<std::size_t>(cols));
  auto at = [&](int i, int j) -> double& { return M[static_cast<std::size_t>(i) * cols + j]; };
  std::fill(M.begin() + static_cast<std::ptrdiff_t>(mk) * cols, M.begin() + static_cast<std::ptrdiff_t>(rows) * cols, 0.0);
  for (int r = 0; r < mk; ++r) {
    const int i = kept[static_cast<std::size_t>(r)];
    for (int j = 0; j < n; ++j) at(r, j) = -box[j] * A(i, j);
    at(r, n) = w[i];
    q[r] = b[i] - shift[i] + S * w[i];
  }
  for (int j = 0; j < n; ++j) {
    at(mk + j, j) = 1;
    q[mk + j] = 2;
  }
  for (int j = 0; j < cols; ++j) N[j] = j;
  // Slack indices as if every row were there (row i's is cols + i): Bland's order unchanged.
  for (int r = 0; r < mk; ++r) B[r] = cols + kept[static_cast<std::size_t>(r)];
  for (int j = 0; j < n; ++j) B[mk + j] = cols + m + j;
  c[n] = 1;  // reduced costs; the objective value itself is read off the solution
  constexpr double tol = 1e-12;
  // At most 8 pivots a row. Under Bland's rule a few LPs stall on degenerate vertices for
  // thousands (cthead h 4: 39 of the joint moves' 722 LPs took 80 % of their pivots, up to
  // 16,000 each, 15 s), and none of those gave a move that was kept (the same mesh with 4 or
  // 8 a row as with 50); the bone's joint move (OptimizePatch.JointMovesGoOnWhereSingleMovesStop)
  // needs 6.
  for (int pivots = 0; pivots < 8 * (m + n); ++pivots) {  // as many as with every row
    // Bland's rule (smallest variable index enters and leaves) cannot cycle. (The largest
    // reduced cost took an eighth of its pivots on cthead's patches, but its optimum, as good
    // in the model, left the bone's joint moves (tests/data/bone_cluster.txt) without a gain.)
    int e = -1;
    for (int j = 0; j < cols; ++j)
      if (c[j] > tol && (e < 0 || N[j] < N[e])) e = j;
    if (e < 0) {
      std::vector<double> y(cols, 0.0);
      for (int i = 0; i < rows; ++i)
        if (B[i] < cols) y[B[i]] = q[i];
      out.d.resize(n);
      for (int j = 0; j < n; ++j) out.d[j] = box[j] * (y[j] - 1.0);
      out.s = y[n] - S;
      out.ok = true;
      return out;
    }
    int r = -1;
    double best = 0;
    for (int i = 0; i < rows; ++i) {
      if (!(at(i, e) > tol)) continue;
      const double ratio = q[i] / at(i, e);
      if (r < 0 || ratio < best || (ratio == best && B[i] < B[r])) r = i, best = ratio;
    }
    if (r < 0) return out;  // unbounded: cannot happen with the box and w > 0
    // Row by row with raw pointers: the same arithmetic as entry by entry (so the same bits),
    // and a third of the joint moves' time on cthead h 3.
    double* R = &at(r, 0);
    const double p = R[e];
    for (int j = 0; j < cols; ++j) R[j] /= p;
    R[e] = 1 / p;
    q[r] /= p;
    eliminate(M.data(), q.data(), rows, cols, r, e, p);
    const double ce = c[e];
    for (int j = 0; j < cols; ++j) c[j] -= ce * R[j];
    c[e] = -ce / p;
    std::swap(B[r], N[e]);
  }
  return out;
}

MaxMin max_min_affine(const std::vector<Affine>& f, const std::vector<double>& w, double box) {
  thread_local std::vector<double> a, b;
  a.resize(3 * f.size()), b.resize(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) {
    for (int j = 0; j < 3; ++j) a[3 * i + j] = f[i].a[j];
    b[i] = f[i].b;
  }
  thread_local std::vector<double> boxes(3);
  boxes.assign(3, box);
  const MaxMinN r = max_min_affine(3, a, b, w, boxes);
  MaxMin out;
  if (!r.ok) return out;
  out.d = Vec3(r.d[0], r.d[1], r.d[2]);
  out.s = r.s;
  out.ok = true;
  return out;
}

Vec3 det_gradient(const Mat3& A, const Vec3& c) {
  // adj(A)ᵀ c, written with the cross products of A's columns.
  return c[0] * A.col(1).cross(A.col(2)) + c[1] * A.col(2).cross(A.col(0)) + c[2] * A.col(0).cross(A.col(1));
}

Affine scaled_frame(const Mat3& A, const Vec3& c, bool value_only) {
  const Vec3 l(A.col(0).norm(), A.col(1).norm(), A.col(2).norm());
  const double prod = l.prod();
  Affine f;
  if (!(prod > 0)) {
    f.b = -2.0;
    return f;
  }
  f.b = A.determinant() / prod;
  if (!value_only) {
    // Column j moves by c_j d: d det = adj(A)ᵀc · d, and each |col j| by c_j col_j·d / |col j|.
    f.a = det_gradient(A, c) / prod;
    for (int j = 0; j < 3; ++j) f.a -= f.b * c[j] / (l[j] * l[j]) * A.col(j);
  }
  return f;
}

double bernstein_norm(const std::array<Vec3, 8>& p) {
  const std::array<double, 27> b = jacobian_bernstein(p);
  return std::max(0.0, *std::max_element(b.begin(), b.end()));
}

void ratio_coefficients(const std::array<Vec3, 8>& p, double weight, double norm, const std::array<bool, 8>& corners,
                        std::array<double, 27>& b, std::array<std::array<Vec3, 27>, 8>* g) {
  const std::array<int, 27>& lattice = lattice_frames();
  std::array<std::array<std::array<double, 27>, 3>, 8> gk;  // per corner and component: transformed alike
  InteriorFrames interior;
  interior_frames(relative_corners(p), 1.0, interior, false);
  // The lattice's determinants and gradients four frames at a time (thread_local: 1.5 KB a call).
  thread_local LatticeFrames lf;
  for (int n = 0; n < 27; ++n) {
    const int t = lattice[static_cast<std::size_t>(n)];
    lf.set_frame(n, t > kCentreFrame ? interior[static_cast<std::size_t>(t - kFrames)] : frame(p, t, 1.0));
  }
  // Each asked corner's gradients (the determinants come with them, the same each time), or
  // the determinants alone.
  bool dets = false;
  for (int k = 0; g && k < 8; ++k) {
    if (!corners[k]) continue;
    for (int n = 0; n < 27; ++n) {
      const Vec3& c = frame_coefficient(lattice[static_cast<std::size_t>(n)], k);
      for (int j = 0; j < 3; ++j) lf.c[static_cast<std::size_t>(j)][static_cast<std::size_t>(n)] = c[j];
    }
    lf.compute(true);
    dets = true;
    for (int n = 0; n < 27; ++n)
      for (int j = 0; j < 3; ++j) gk[k][j][n] = (weight / norm) * lf.grad[static_cast<std::size_t>(j)][static_cast<std::size_t>(n)];
  }
  if (!dets) lf.compute(false);
  for (int n = 0; n < 27; ++n) b[n] = weight * lf.det[static_cast<std::size_t>(n)] / norm;
  lattice_to_bernstein(b);
  if (!g) return;
  for (int k = 0; k < 8; ++k) {
    if (!corners[k]) continue;
    for (int j = 0; j < 3; ++j) lattice_to_bernstein(gk[k][j]);
    for (int n = 0; n < 27; ++n) (*g)[k][n] = Vec3(gk[k][0][n], gk[k][1][n], gk[k][2][n]);
  }
}

namespace {

// Bit k of frame_corners()[t]: frame t sees corner k (a non-zero coefficient). A table, not
// frame_coefficient() per corner: find_infeasible() asks it for every free vertex's frames.
const std::array<std::uint8_t, kFrames>& frame_corners() {
  static const std::array<std::uint8_t, kFrames> mask = [] {
    std::array<std::uint8_t, kFrames> m{};
    for (int t = 0; t < kFrames; ++t)
      for (int k = 0; k < 8; ++k)
        if (!frame_coefficient(t, k).isZero()) m[static_cast<std::size_t>(t)] |= static_cast<std::uint8_t>(1u << k);
    return m;
  }();
  return mask;
}

}  // namespace

std::vector<Affine> vertex_frames(const HexMesh& mesh, const Incidence& inc, const std::vector<double>& inv_len, Index v,
                                  const std::vector<std::uint8_t>* fixed, const std::vector<std::uint8_t>* skip,
                                  std::vector<Index>* hex_of) {
  const std::array<std::uint8_t, kFrames>& sees = frame_corners();
  std::vector<Affine> out;
  for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i) {
    const Index h = inc.ids[i];
    if (skip && (*skip)[h]) continue;
    const Hex& hx = mesh.hexes[h];
    int k = 0;
    while (hx[k] != v) ++k;
    // The corners of h that are free, v's own excepted (all of them without `fixed`).
    unsigned free_others = 0;
    for (int j = 0; j < 8; ++j)
      if (j != k && (!fixed || !(*fixed)[hx[j]])) free_others |= 1u << j;
    const double il = inv_len[h];
    std::array<Vec3, 8> p;
    bool have_corners = false;
    for (int t = 0; t < kFrames; ++t) {
      const unsigned m = sees[static_cast<std::size_t>(t)];
      if (!((m >> k) & 1u)) continue;          // frame t does not see v
      if (fixed && (m & free_others)) continue;  // v is not its only free vertex
      if (!have_corners) p = mesh.corners(h), have_corners = true;
      const Vec3& c = frame_coefficient(t, k);
      const Mat3 A = frame(p, t, il);
      Affine a;
      a.b = A.determinant();
      a.a = il * det_gradient(A, c);
      out.push_back(a);
      if (hex_of) hex_of->push_back(h);
    }
  }
  return out;
}

std::size_t max_min_sweep(HexMesh& mesh, const VertexColoring& coloring, const Incidence& inc,
                          const std::vector<double>& inv_len, const std::vector<std::uint8_t>& active,
                          const std::vector<std::uint8_t>* skip) {
  std::size_t moves = 0;
  std::vector<std::uint8_t> moved;
  for (const std::vector<Index>& color : coloring.colors) {
    moved.assign(color.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, color.size(), 16), [&](const auto& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        const Index v = color[i];
        if (!active[v]) continue;
        const std::vector<Affine> f = vertex_frames(mesh, inc, inv_len, v, nullptr, skip);
        if (f.empty()) continue;
        double now = f[0].b;
        for (const Affine& a : f) now = std::min(now, a.b);
        // Half an edge: the determinants are exactly affine in v, but the other terms of the
        // later stages are not, and a long jump would trade shape for a tiny gain.
        const MaxMin r = max_min_affine(f, std::vector<double>(f.size(), 1.0), 0.5 * mean_edge_at(mesh, inc, v));
        if (!r.ok || !(r.s > now + 1e-12)) continue;
        // The hexes around v that are valid now must stay so: with a frame that cannot become
        // positive (a hex stuck inverted), the max–min place would pull valid frames down to
        // its negative level, trading one inverted hex for several.
        std::vector<std::uint8_t> valid_before;
        for (Index j = inc.offsets[v]; j < inc.offsets[v + 1]; ++j)
          valid_before.push_back(hex_feasible(mesh.corners(inc.ids[j]), inv_len[inc.ids[j]]));
        const Vec3 old = mesh.points[v];
        mesh.points[v] = old + r.d;
        // Re-evaluated rather than trusted: rounding must not turn the move into a loss.
        double after = 1e300;
        for (const Affine& a : vertex_frames(mesh, inc, inv_len, v, nullptr, skip)) after = std::min(after, a.b);
        bool keeps_valid = true;
        for (Index j = inc.offsets[v]; j < inc.offsets[v + 1]; ++j)
          if (valid_before[j - inc.offsets[v]] && !hex_feasible(mesh.corners(inc.ids[j]), inv_len[inc.ids[j]]))
            keeps_valid = false;
        if (after > now && keeps_valid) moved[i] = 1;
        else mesh.points[v] = old;
      }
    });
    for (std::uint8_t m : moved) moves += m;
  }
  return moves;
}

double mean_edge_at(const HexMesh& mesh, const Incidence& inc, Index v) {
  double sum = 0;
  int n = 0;
  for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i)
    for (const auto& e : kHexEdges) {
      const Hex& hx = mesh.hexes[inc.ids[i]];
      if (hx[e[0]] != v && hx[e[1]] != v) continue;
      sum += (mesh.points[hx[e[0]]] - mesh.points[hx[e[1]]]).norm();
      ++n;
    }
  return n ? sum / n : 0.0;
}

}  // namespace isohex::opt
