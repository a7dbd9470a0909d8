// Bernstein bounds of the trilinear hex's Jacobian determinant, adaptive subdivision, and
// the whole-mesh evaluations built on them.
#include "isohex/quality/jacobian_bounds.hpp"

#include "isohex/mesh/topology.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/internal/multiversion.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <tuple>

namespace isohex {

namespace {

bool all_finite(const std::array<Vec3, 8>& p) {
  for (const Vec3& x : p)
    if (!x.allFinite()) return false;
  return true;
}

// GCC's vector extensions (AVX where the kernel's clone has it, SSE pairs otherwise); only
// inside always-inline bodies, so no vector crosses a call.
#pragma GCC diagnostic ignored "-Wpsabi"
using d4 = double __attribute__((vector_size(32)));

// The smallest and largest Bernstein coefficient and the smallest sample of a box. A
// non-finite value anywhere (a non-finite corner, or an overflow) makes min_s NaN: never
// certified, and a ratio bound of -1.
struct Extremes {
  double min_b, max_b, min_s;
};
Extremes extremes(const std::array<double, 27>& b, const std::array<double, 27>& s) {
  Extremes e{b[0], b[0], s[0]};
  double sum = 0;
  for (int i = 0; i < 27; ++i) {
    e.min_b = std::min(e.min_b, b[i]), e.max_b = std::max(e.max_b, b[i]), e.min_s = std::min(e.min_s, s[i]);
    sum += b[i] + s[i];
  }
  if (!std::isfinite(sum)) e.min_s = std::numeric_limits<double>::quiet_NaN();
  if (e.min_b == 0) e.min_b = 0.0;  // +0 whichever zero came first: ratio_bound()'s sign
  return e;
}

// Corners relative to corner 0: det J is translation invariant, and differences keep the
// digits of elements far from the origin.
std::array<Vec3, 8> relative(const std::array<Vec3, 8>& p) {
  std::array<Vec3, 8> q;
  for (int k = 0; k < 8; ++k) q[k] = p[k] - p[0];
  return q;
}

// The three edge vectors of the trilinear map: ∂x/∂u depends on (v, w) only, ∂x/∂v on (u, w),
// ∂x/∂w on (u, v), so a lattice of 27 points needs 9 of each (bernstein_box()).
Vec3 edge_u(const std::array<Vec3, 8>& p, double v, double w) {
  const double v0 = 1 - v, w0 = 1 - w;
  return v0 * w0 * (p[1] - p[0]) + v * w0 * (p[2] - p[3]) + v0 * w * (p[5] - p[4]) + v * w * (p[6] - p[7]);
}
Vec3 edge_v(const std::array<Vec3, 8>& p, double u, double w) {
  const double u0 = 1 - u, w0 = 1 - w;
  return u0 * w0 * (p[3] - p[0]) + u * w0 * (p[2] - p[1]) + u0 * w * (p[7] - p[4]) + u * w * (p[6] - p[5]);
}
Vec3 edge_w(const std::array<Vec3, 8>& p, double u, double v) {
  const double u0 = 1 - u, v0 = 1 - v;
  return u0 * v0 * (p[4] - p[0]) + u * v0 * (p[5] - p[1]) + u * v * (p[6] - p[2]) + u0 * v * (p[7] - p[3]);
}

double det_at(const std::array<Vec3, 8>& p, double u, double v, double w) {
  return edge_u(p, v, w).dot(edge_v(p, u, w).cross(edge_w(p, u, v)));
}

// In place: the lattice values of a triquadratic to its Bernstein coefficients (per axis, the
// quadratic through the values at 0, 1/2, 1 has Bernstein coefficients f(0),
// 2 f(1/2) - (f(0) + f(1))/2, f(1)).
[[gnu::always_inline]] inline void lattice_to_bernstein_body(double* f) {
  const auto line = [&](int a, int b, int c) { f[b] = 2 * f[b] - 0.5 * (f[a] + f[c]); };
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j) line(3 * j + 9 * k, 1 + 3 * j + 9 * k, 2 + 3 * j + 9 * k);
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 3; ++i) line(i + 9 * k, i + 3 + 9 * k, i + 6 + 9 * k);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) line(i + 3 * j, i + 3 * j + 9, i + 3 * j + 18);
}

// det J at the 27 lattice points of a sub-box, b[i + 3j + 9k] = xu[j + 3k] · (xv[i + 3k] ×
// xw[i + 3j]): the operands laid out side by side first (structure of arrays), so that the
// compiler packs the 27 triple products into SIMD instructions; each is Eigen's cross then
// dot, the same operations in the same order, so the same bits (tested).
[[gnu::always_inline]] inline void lattice_dets_body(const std::array<Vec3, 9>& xu, const std::array<Vec3, 9>& xv,
                                                     const std::array<Vec3, 9>& xw, std::array<double, 27>& out) {
  alignas(64) double U[3][28], V[3][28], W[3][28], b[28];
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        const int n = i + 3 * j + 9 * k;
        for (int c = 0; c < 3; ++c) {
          U[c][n] = xu[j + 3 * k][c];
          V[c][n] = xv[i + 3 * k][c];
          W[c][n] = xw[i + 3 * j][c];
        }
      }
  for (int c = 0; c < 3; ++c) U[c][27] = V[c][27] = W[c][27] = 0;  // a 28th lane: whole vectors
  for (int n = 0; n < 28; ++n) {
    const double cx = V[1][n] * W[2][n] - V[2][n] * W[1][n];
    const double cy = V[2][n] * W[0][n] - V[0][n] * W[2][n];
    const double cz = V[0][n] * W[1][n] - V[1][n] * W[0][n];
    b[n] = U[0][n] * cx + U[1][n] * cy + U[2][n] * cz;
  }
  for (int n = 0; n < 27; ++n) out[n] = b[n];
}

// A bilinear blend of one component of the edge vectors a (at parameters 0, 0), b (1, 0),
// c (0, 1) and d (1, 1) on the 3×3 lattice of 0, 1/2, 1 (x[i + 3j] at (i/2, j/2)); the centre
// x[4] is the caller's, whose sum it orders as edge_u() and the others do.
[[gnu::always_inline]] inline void unit_lattice(double a, double b, double c, double d, double* x) {
  x[0] = a, x[2] = b, x[6] = c, x[8] = d;
  x[1] = 0.5 * a + 0.5 * b;
  x[7] = 0.5 * c + 0.5 * d;
  x[3] = 0.5 * a + 0.5 * c;
  x[5] = 0.5 * b + 0.5 * d;
}

// The whole element (most calls), four lanes along u: lattice point (i, j, k) is lane i of
// vector j + 3k (lane 3 a zero pad), so that xu[j + 3k] is one broadcast and xv[i + 3k],
// xw[i + 3j] are three vectors each, with no shuffling of 27 lanes through memory; the
// Bernstein passes along v and w are whole-vector operations. edge_u() and the others at 0,
// 1/2 and 1 are the element's edges and their halves and quarters: the same sums in the same
// order as det_at() without the zero terms, and each lane the same triple product and the
// same pass as the scalar code, so the same bits (tested). Returns the extremes of the
// samples and coefficients; writes them to `samples` and `coef` where those are not null.
// Every certificate runs this.
[[gnu::always_inline]] inline Extremes whole_element_body(const std::array<Vec3, 8>& q, double* samples, double* coef) {
  d4 U[3][9], V[3][3], W[3][3];
  for (int c = 0; c < 3; ++c) {
    double u[9], v[9], w[9];
    const double ua = q[1][c] - q[0][c], ub = q[2][c] - q[3][c], uc = q[5][c] - q[4][c], ud = q[6][c] - q[7][c];
    const double va = q[3][c] - q[0][c], vb = q[2][c] - q[1][c], vc = q[7][c] - q[4][c], vd = q[6][c] - q[5][c];
    const double wa = q[4][c] - q[0][c], wb = q[5][c] - q[1][c], wc = q[7][c] - q[3][c], wd = q[6][c] - q[2][c];
    unit_lattice(ua, ub, uc, ud, u);
    u[4] = 0.25 * ua + 0.25 * ub + 0.25 * uc + 0.25 * ud;
    unit_lattice(va, vb, vc, vd, v);
    v[4] = 0.25 * va + 0.25 * vb + 0.25 * vc + 0.25 * vd;
    unit_lattice(wa, wb, wc, wd, w);
    w[4] = 0.25 * wa + 0.25 * wb + 0.25 * wd + 0.25 * wc;
    for (int m = 0; m < 9; ++m) U[c][m] = d4{u[m], u[m], u[m], u[m]};
    for (int t = 0; t < 3; ++t) {
      V[c][t] = d4{v[3 * t], v[3 * t + 1], v[3 * t + 2], 0.0};
      W[c][t] = d4{w[3 * t], w[3 * t + 1], w[3 * t + 2], 0.0};
    }
  }
  d4 S[9];
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j) {
      const int m = j + 3 * k;
      const d4 cx = V[1][k] * W[2][j] - V[2][k] * W[1][j];
      const d4 cy = V[2][k] * W[0][j] - V[0][k] * W[2][j];
      const d4 cz = V[0][k] * W[1][j] - V[1][k] * W[0][j];
      S[m] = U[0][m] * cx + U[1][m] * cy + U[2][m] * cz;
    }
  Extremes e;
  // lane 3 (the pad) takes lane 0's value: it changes no minimum or maximum
  const auto real = [](d4 x) { return d4{x[0], x[1], x[2], x[0]}; };
  d4 lo = real(S[0]), acc{0, 0, 0, 0};
  for (int m = 0; m < 9; ++m) {
    const d4 x = real(S[m]);
    lo = x < lo ? x : lo;
    acc += x;
    if (samples)
      for (int i = 0; i < 3; ++i) samples[3 * m + i] = S[m][i];
  }
  e.min_s = std::min(std::min(lo[0], lo[1]), lo[2]);
  // lattice_to_bernstein(): along u within each vector, then along v and w between vectors
  for (int m = 0; m < 9; ++m) S[m][1] = 2 * S[m][1] - 0.5 * (S[m][0] + S[m][2]);
  for (int k = 0; k < 3; ++k) S[1 + 3 * k] = 2 * S[1 + 3 * k] - 0.5 * (S[3 * k] + S[2 + 3 * k]);
  for (int j = 0; j < 3; ++j) S[j + 3] = 2 * S[j + 3] - 0.5 * (S[j] + S[j + 6]);
  lo = real(S[0]);
  d4 hi = lo;
  for (int m = 0; m < 9; ++m) {
    const d4 x = real(S[m]);
    lo = x < lo ? x : lo;
    hi = x > hi ? x : hi;
    acc += x;
    if (coef)
      for (int i = 0; i < 3; ++i) coef[3 * m + i] = S[m][i];
  }
  e.min_b = std::min(std::min(lo[0], lo[1]), lo[2]);
  e.max_b = std::max(std::max(hi[0], hi[1]), hi[2]);
  if (!std::isfinite((acc[0] + acc[1]) + (acc[2] + acc[3]))) e.min_s = std::numeric_limits<double>::quiet_NaN();
  if (e.min_b == 0) e.min_b = 0.0;  // +0 whichever zero came first: ratio_bound()'s sign
  return e;
}

#if ISOHEX_HAVE_FMV
// AVX2 where the CPU has it (no FMA: the library builds with -ffp-contract=off); AVX-512 was
// no faster on 28 lanes.
[[gnu::target("default")]] void lattice_dets(const std::array<Vec3, 9>& xu, const std::array<Vec3, 9>& xv,
                                             const std::array<Vec3, 9>& xw, std::array<double, 27>& out) {
  lattice_dets_body(xu, xv, xw, out);
}
[[gnu::target("avx2")]] void lattice_dets(const std::array<Vec3, 9>& xu, const std::array<Vec3, 9>& xv,
                                          const std::array<Vec3, 9>& xw, std::array<double, 27>& out) {
  lattice_dets_body(xu, xv, xw, out);
}
[[gnu::target("default")]] Extremes whole_element(const std::array<Vec3, 8>& q, double* samples, double* coef) {
  return whole_element_body(q, samples, coef);
}
[[gnu::target("avx2")]] Extremes whole_element(const std::array<Vec3, 8>& q, double* samples, double* coef) {
  return whole_element_body(q, samples, coef);
}
#else
void lattice_dets(const std::array<Vec3, 9>& xu, const std::array<Vec3, 9>& xv, const std::array<Vec3, 9>& xw,
                  std::array<double, 27>& out) {
  lattice_dets_body(xu, xv, xw, out);
}
Extremes whole_element(const std::array<Vec3, 8>& q, double* samples, double* coef) {
  return whole_element_body(q, samples, coef);
}
#endif

// The 27 samples on the lattice of [lo, hi] and their Bernstein coefficients; `samples`
// (values actually taken by det J) may be null. (The same values as det_at() at each point,
// bit for bit: its edge vectors, each computed once.)
std::array<double, 27> bernstein_box(const std::array<Vec3, 8>& q, const Vec3& lo, const Vec3& hi,
                                     std::array<double, 27>* samples) {
  std::array<double, 27> b;
  if (lo == Vec3::Zero() && hi == Vec3::Ones()) {
    whole_element(q, samples ? samples->data() : nullptr, b.data());
    return b;
  }
  const Vec3 mid = 0.5 * (lo + hi);
  const double us[3] = {lo[0], mid[0], hi[0]}, vs[3] = {lo[1], mid[1], hi[1]}, ws[3] = {lo[2], mid[2], hi[2]};
  std::array<Vec3, 9> xu, xv, xw;  // xu[j + 3k] at (v_j, w_k), xv[i + 3k] at (u_i, w_k), xw[i + 3j] at (u_i, v_j)
  for (int b2 = 0; b2 < 3; ++b2)
    for (int a = 0; a < 3; ++a) {
      xu[a + 3 * b2] = edge_u(q, vs[a], ws[b2]);
      xv[a + 3 * b2] = edge_v(q, us[a], ws[b2]);
      xw[a + 3 * b2] = edge_w(q, us[a], vs[b2]);
    }
  lattice_dets(xu, xv, xw, b);
  if (samples) *samples = b;
  lattice_to_bernstein(b);
  return b;
}

// Child c of the box [lo, hi]: along axis a its upper half when bit a of c is set.
std::pair<Vec3, Vec3> child(const Vec3& lo, const Vec3& hi, int c) {
  const Vec3 mid = 0.5 * (lo + hi);
  Vec3 l, h;
  for (int a = 0; a < 3; ++a) {
    const bool upper = (c >> a) & 1;
    l[a] = upper ? mid[a] : lo[a];
    h[a] = upper ? hi[a] : mid[a];
  }
  return {l, h};
}

struct Box {
  Vec3 lo, hi;
  double min_coef, max_coef;
};

// Adaptive subdivision: two heaps over the leaves (by smallest and by largest coefficient),
// with lazy deletion of split leaves. Deterministic: ties are broken by leaf number.
class Subdivision {
 public:
  Subdivision(const std::array<Vec3, 8>& p) : q_(relative(p)) { add(Vec3::Zero(), Vec3::Ones()); }

  JacobianBounds run(const JacobianBoundOptions& o) {
    JacobianBounds r;
    for (;;) {
      r.min_lower = boxes_[low_.top().second].min_coef;
      r.max_upper = boxes_[high_.top().second].max_coef;
      r.min_upper = min_sample_;
      r.max_lower = max_sample_;
      if (o.sign_only && (r.min_lower > 0 || r.min_upper <= 0)) break;
      const double scale = std::max(std::abs(min_sample_), std::abs(max_sample_));
      const double gap_min = r.min_upper - r.min_lower, gap_max = r.max_upper - r.max_lower;
      // Within tolerance, but never with the sign still open: a valid hex whose minimum is a
      // tiny fraction of its maximum must still be certified (as Gmsh does).
      const bool decided = r.min_lower > 0 || r.min_upper <= 0;
      if (!o.sign_only && decided && gap_min <= o.tolerance * scale && gap_max <= o.tolerance * scale) break;
      if (r.subdivisions >= o.max_subdivisions || !(scale > 0)) break;
      const bool for_min = o.sign_only || !decided || gap_min >= gap_max;
      std::size_t leaf;
      if (for_min) {
        leaf = low_.top().second;
        low_.pop();
      } else {
        leaf = high_.top().second;
        high_.pop();
      }
      split(leaf);
      ++r.subdivisions;
    }
    return r;
  }

 private:
  void add(const Vec3& lo, const Vec3& hi) {
    std::array<double, 27> s;
    const std::array<double, 27> b = bernstein_box(q_, lo, hi, &s);
    Box box{lo, hi, b[0], b[0]};
    for (double c : b) {
      box.min_coef = std::min(box.min_coef, c);
      box.max_coef = std::max(box.max_coef, c);
    }
    for (double x : s) {
      min_sample_ = std::min(min_sample_, x);
      max_sample_ = std::max(max_sample_, x);
    }
    const std::size_t id = boxes_.size();
    boxes_.push_back(box);
    alive_.push_back(1);
    low_.push({box.min_coef, id});
    high_.push({-box.max_coef, id});
  }

  void split(std::size_t leaf) {
    alive_[leaf] = 0;
    const Box b = boxes_[leaf];
    for (int c = 0; c < 8; ++c) {
      const auto [lo, hi] = child(b.lo, b.hi, c);
      add(lo, hi);
    }
    drop_dead();
  }

  // Leaves split through the other heap are dropped when they surface.
  void drop_dead() {
    while (!alive_[low_.top().second]) low_.pop();
    while (!alive_[high_.top().second]) high_.pop();
  }

  using Entry = std::pair<double, std::size_t>;
  using MinHeap = std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>>;
  std::array<Vec3, 8> q_;
  std::vector<Box> boxes_;
  std::vector<std::uint8_t> alive_;
  MinHeap low_, high_;  // high_ holds −max so that its top is the largest coefficient
  double min_sample_ = std::numeric_limits<double>::infinity();
  double max_sample_ = -std::numeric_limits<double>::infinity();
};

// Gauss–Legendre nodes and weights on [0, 1].
constexpr double kG2 = 0.21132486540518711775;  // (1 − 1/√3)/2
constexpr std::array<double, 4> kG4x = {0.069431844202973712, 0.33000947820757187, 0.66999052179242813,
                                        0.93056815579702629};
constexpr std::array<double, 4> kG4w = {0.17392742256872693, 0.32607257743127307, 0.32607257743127307,
                                        0.17392742256872693};

// ∫ |det J| over the element: exact (the signed volume) when it is certified valid, else
// Gauss 4×4×4 on each of 4×4×4 sub-boxes (|det J| is not a polynomial where it changes sign).
double abs_volume(const std::array<Vec3, 8>& p) {
  if (certified_valid(p)) return volume(p);
  const std::array<Vec3, 8> q = relative(p);
  constexpr int n = 4;
  double sum = 0;
  for (int c = 0; c < n * n * n; ++c) {
    const int a = c % n, b = (c / n) % n, d = c / (n * n);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        for (int k = 0; k < 4; ++k)
          sum += kG4w[i] * kG4w[j] * kG4w[k] *
                 std::abs(det_at(q, (a + kG4x[i]) / n, (b + kG4x[j]) / n, (d + kG4x[k]) / n));
  }
  return sum / (n * n * n);
}

// certified_valid() from the element's own extremes `root` (box [0,1]^3): depth first on the
// boxes whose coefficients are not all above the floor; any sample at or below it decides "not
// certified" at once.
bool certify(const std::array<Vec3, 8>& q, const Extremes& root, double floor, int max_subdivisions) {
  if (!(root.min_s > floor)) return false;
  if (root.min_b > floor) return true;  // most calls: the element's own coefficients suffice
  if (max_subdivisions < 1) return false;
  std::vector<std::pair<Vec3, Vec3>> stack;
  for (int c = 0; c < 8; ++c) stack.push_back(child(Vec3::Zero(), Vec3::Ones(), c));
  int splits = 1;
  std::array<double, 27> s;
  while (!stack.empty()) {
    const auto [lo, hi] = stack.back();
    stack.pop_back();
    const std::array<double, 27> b = bernstein_box(q, lo, hi, &s);
    const Extremes e = extremes(b, s);
    if (!(e.min_s > floor)) return false;
    if (!(e.min_b > floor)) {
      if (++splits > max_subdivisions) return false;
      for (int c = 0; c < 8; ++c) stack.push_back(child(lo, hi, c));
    }
  }
  return true;
}

// min / max of the element's coefficients (jacobian_ratio_bound()).
double ratio_bound(const Extremes& e) {
  if (std::isnan(e.min_s)) return -1.0;  // a non-finite corner
  if (!(e.max_b > 0)) return e.max_b == 0 && e.min_b == 0 ? 0.0 : -1.0;
  return std::max(-1.0, e.min_b / e.max_b);
}

// min / max clamped to [-1, 1]; an element negative everywhere is -1, a flat one 0.
double ratio_of(const JacobianBounds& b) {
  if (!(b.max_upper > 0)) return b.max_upper == 0 && b.min_lower == 0 ? 0.0 : -1.0;
  return std::max(-1.0, std::min(1.0, b.min_lower / b.max_upper));
}

}  // namespace

void lattice_to_bernstein(std::array<double, 27>& f) { lattice_to_bernstein_body(f.data()); }

double jacobian_determinant(const std::array<Vec3, 8>& p, double u, double v, double w) {
  return det_at(relative(p), u, v, w);
}

std::array<double, 27> jacobian_bernstein(const std::array<Vec3, 8>& p, const Vec3& lo, const Vec3& hi) {
  return bernstein_box(relative(p), lo, hi, nullptr);
}

JacobianBounds jacobian_bounds(const std::array<Vec3, 8>& p, const JacobianBoundOptions& options) {
  if (!all_finite(p)) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan, nan, nan, 0};  // neither valid() nor invalid(): undecidable
  }
  return Subdivision(p).run(options);
}

double jacobian_ratio(const std::array<Vec3, 8>& p) { return ratio_of(jacobian_bounds(p)); }

double gauss_min_jacobian(const std::array<Vec3, 8>& p) {
  const std::array<Vec3, 8> q = relative(p);
  double m = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 8; ++c)
    m = std::min(m, det_at(q, c & 1 ? 1 - kG2 : kG2, c & 2 ? 1 - kG2 : kG2, c & 4 ? 1 - kG2 : kG2));
  return m;
}

namespace {

// certified_valid() with, unless ratio_floor is -inf, the ratio floor tested first on the same
// coefficients; `ratio` (may be null) gets their ratio bound.
bool certified_above(const std::array<Vec3, 8>& p, double floor, int max_subdivisions, double ratio_floor,
                     double* ratio = nullptr) {
  // A non-finite corner is never valid: whole_element() makes its min_s NaN.
  const std::array<Vec3, 8> q = relative(p);
  const Extremes e = whole_element(q, nullptr, nullptr);
  const double rb = ratio_bound(e);
  if (ratio) *ratio = rb;
  if (rb < ratio_floor) return false;
  return certify(q, e, floor, max_subdivisions);
}

}  // namespace

bool certified_valid_above_ratio(const std::array<Vec3, 8>& p, double floor, double ratio_floor, double* ratio) {
  return certified_above(p, floor, kCertifySubdivisions, ratio_floor, ratio);
}

bool certified_valid(const std::array<Vec3, 8>& p, double floor, int max_subdivisions) {
  return certified_above(p, floor, max_subdivisions, -std::numeric_limits<double>::infinity());
}

double certified_scaled_jacobian(const std::array<Vec3, 8>& p) {
  const double sj = scaled_jacobian(p);
  if (is_degenerate(sj) || !(sj > 0)) return sj;
  return certified_valid(p) ? sj : 0.0;
}

double jacobian_ratio_bound(const std::array<Vec3, 8>& p) {
  return ratio_bound(whole_element(relative(p), nullptr, nullptr));
}

CertifiedQuality certified_quality(const std::array<Vec3, 8>& p) {
  const std::array<Vec3, 8> q = relative(p);
  const Extremes e = whole_element(q, nullptr, nullptr);
  CertifiedQuality r{scaled_jacobian(p), ratio_bound(e)};
  if (!is_degenerate(r.scaled_jacobian) && r.scaled_jacobian > 0 && !certify(q, e, 0, kCertifySubdivisions))
    r.scaled_jacobian = 0;
  return r;
}

std::vector<double> certified_scaled_jacobians(const HexMesh& mesh) {
  std::vector<double> sj = scaled_jacobians(mesh);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sj.size(), 1024), [&](const auto& range) {
    for (std::size_t h = range.begin(); h != range.end(); ++h)
      if (sj[h] > 0 && !is_degenerate(sj[h]) && !certified_valid(mesh.corners(static_cast<Index>(h)))) sj[h] = 0.0;
  });
  return sj;
}

MeshJacobians mesh_jacobians(const HexMesh& mesh) {
  const std::size_t n = mesh.hexes.size();
  MeshJacobians r{std::vector<double>(n), std::vector<double>(n), std::vector<std::uint8_t>(n)};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const auto& range) {
    for (std::size_t h = range.begin(); h != range.end(); ++h) {
      const auto p = mesh.corners(static_cast<Index>(h));
      const JacobianBounds b = jacobian_bounds(p);
      r.ratio[h] = ratio_of(b);
      r.valid[h] = b.valid() ? 1 : 0;
      r.gauss_min[h] = gauss_min_jacobian(p);
    }
  });
  return r;
}

VolumeBalance volume_balance(const HexMesh& mesh) {
  VolumeBalance r;
  const std::size_t n = mesh.hexes.size();
  std::vector<double> abs_v(n), signed_v(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const auto& range) {
    for (std::size_t h = range.begin(); h != range.end(); ++h) {
      const auto p = mesh.corners(static_cast<Index>(h));
      signed_v[h] = volume(p);
      abs_v[h] = abs_volume(p);
    }
  });
  for (std::size_t h = 0; h < n; ++h) {  // in hex order: the same bits for any thread count
    r.hexes += abs_v[h];
    r.signed_hexes += signed_v[h];
  }
  // (1/3) ∮ x·n dA over the bilinear boundary patches, about the first vertex for precision:
  // the integrand has degree 2 in each parameter, so 2×2 Gauss points are exact.
  const Vec3 o = mesh.points.empty() ? Vec3::Zero() : mesh.points[0];
  for (const Quad& q : boundary_quads(mesh)) {
    const Vec3 a = mesh.points[q[0]] - o, b = mesh.points[q[1]] - o, c = mesh.points[q[2]] - o, d = mesh.points[q[3]] - o;
    for (int i = 0; i < 4; ++i) {
      const double s = i & 1 ? 1 - kG2 : kG2, t = i & 2 ? 1 - kG2 : kG2;
      const Vec3 x = (1 - s) * (1 - t) * a + s * (1 - t) * b + s * t * c + (1 - s) * t * d;
      const Vec3 xs = (1 - t) * (b - a) + t * (c - d), xt = (1 - s) * (d - a) + s * (c - b);
      r.enclosed += 0.25 * x.dot(xs.cross(xt)) / 3;
    }
  }
  return r;
}

}  // namespace isohex
