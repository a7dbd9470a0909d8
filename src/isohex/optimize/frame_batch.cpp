// The frames around a vertex and the terms of a line search's model, four at a time.
#include "isohex/internal/multiversion.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/frame_terms.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

namespace isohex::opt {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

[[gnu::always_inline]] inline d4 load(const double* p) {
  d4 x;
  std::memcpy(&x, p, sizeof x);
  return x;
}
[[gnu::always_inline]] inline void store(double* p, d4 x) { std::memcpy(p, &x, sizeof x); }
// (Helpers, not lambdas: a lambda's call operator is one function for both instruction sets'
// kernels, and one taking or returning a vector would change its ABI between them.)
[[gnu::always_inline]] inline d4 field(const double* block, int f) { return load(block + f * 4); }
[[gnu::always_inline]] inline void set_field(double* block, int f, d4 x) { store(block + f * 4, x); }
[[gnu::always_inline]] inline d4 lanes(int block, const std::array<double, LatticeFrames::kLanes>& x) {
  return load(&x[static_cast<std::size_t>(4 * block)]);
}

// |A|² and det A of four frames at once (A(r, c) = a[r + 3c] lane by lane), in the orders of
// Eigen's squaredNorm() and determinant() for a 3×3 matrix: each lane the scalar bits.
[[gnu::always_inline]] inline d4 squared_norms(const d4 (&a)[9]) {
  return (((a[0] * a[0] + a[2] * a[2]) + (a[4] * a[4] + a[6] * a[6])) +
          ((a[1] * a[1] + a[3] * a[3]) + (a[5] * a[5] + a[7] * a[7]))) +
         a[8] * a[8];
}
[[gnu::always_inline]] inline d4 determinants(const d4 (&a)[9]) {
  return (a[0] * (a[4] * a[8] - a[7] * a[5]) - a[3] * (a[1] * a[8] - a[7] * a[2])) + a[6] * (a[1] * a[5] - a[4] * a[2]);
}

// One block of four frames. Each expression is the one the scalar code evaluated (Eigen's
// orders for a 3×3 matrix's squaredNorm(), determinant(), A·c and cross products; the
// gradient of a corner's own frame or of a unit coefficient is this general form with its
// factors 1, 0 and −1, exactly), so a lane's bits are those of the scalar evaluation.
template <bool kUntangle>
[[gnu::always_inline]] inline void frame_block(double* b, double lambda) {
  using F_ = FrameBatch;
  d4 a[9];
  for (int e = 0; e < 9; ++e) a[e] = field(b, F_::kA + e);
  const d4 a0 = a[0], a1 = a[1], a2 = a[2], a3 = a[3], a4 = a[4], a5 = a[5], a6 = a[6], a7 = a[7], a8 = a[8];
  const d4 c0 = field(b, F_::kC), c1 = field(b, F_::kC + 1), c2 = field(b, F_::kC + 2);
  const d4 il = field(b, F_::kIl), sq = field(b, F_::kSq);
  const d4 F = squared_norms(a), D = determinants(a);
  // ∇F = 2·il·A·c (Eigen's scaled product: the factor on A's entries, rows 0 and 1 summed left
  // to right, row 2 its last two first)
  const d4 il2 = 2.0 * il;
  const d4 gF0 = ((il2 * a0) * c0 + (il2 * a3) * c1) + (il2 * a6) * c2;
  const d4 gF1 = ((il2 * a1) * c0 + (il2 * a4) * c1) + (il2 * a7) * c2;
  const d4 gF2 = (il2 * a2) * c0 + ((il2 * a5) * c1 + (il2 * a8) * c2);
  // ∇D = il·(c0·(col1 × col2) + c1·(col2 × col0) + c2·(col0 × col1)), with A(r, c) = a[r + 3c]
  const d4 x0 = a4 * a8 - a5 * a7, x1 = a5 * a6 - a3 * a8, x2 = a3 * a7 - a4 * a6;
  const d4 y0 = a7 * a2 - a8 * a1, y1 = a8 * a0 - a6 * a2, y2 = a6 * a1 - a7 * a0;
  const d4 z0 = a1 * a5 - a2 * a4, z1 = a2 * a3 - a0 * a5, z2 = a0 * a4 - a1 * a3;
  const d4 gD0 = il * ((c0 * x0 + c1 * y0) + c2 * z0);
  const d4 gD1 = il * ((c0 * x1 + c1 * y1) + c2 * z1);
  const d4 gD2 = il * ((c0 * x2 + c1 * y2) + c2 * z2);
  TermValue<d4> s;
  if constexpr (kUntangle) s = untangle_term(F, D, field(b, F_::kEps), lambda);
  else s = shape_term(F, D);
  set_field(b, F_::kF, F), set_field(b, F_::kD, D), set_field(b, F_::kValue, s.f);
  set_field(b, F_::kGrad, s.fF * gF0 + s.fD * gD0);
  set_field(b, F_::kGrad + 1, s.fF * gF1 + s.fD * gD1);
  set_field(b, F_::kGrad + 2, s.fF * gF2 + s.fD * gD2);
  set_field(b, F_::kIdentity, s.fF * 2.0 * il * il * sq);
  const d4 gF[3] = {gF0, gF1, gF2}, gD[3] = {gD0, gD1, gD2};
  int e = F_::kHessian;
  for (int j = 0; j < 3; ++j)
    for (int i = j; i < 3; ++i) set_field(b, e++, s.fFD * (gF[i] * gD[j] + gD[i] * gF[j]) + (s.fDD * gD[i]) * gD[j]);
  set_field(b, F_::kGF, gF0), set_field(b, F_::kGF + 1, gF1), set_field(b, F_::kGF + 2, gF2);
  set_field(b, F_::kGD, gD0), set_field(b, F_::kGD + 1, gD1), set_field(b, F_::kGD + 2, gD2);
  set_field(b, F_::kCc, il * il * sq);
}

[[gnu::always_inline]] inline void frames_body(double* data, std::size_t blocks, bool untangle, double lambda) {
  for (std::size_t k = 0; k < blocks; ++k) {
    if (untangle) frame_block<true>(data + k * FrameBatch::kBlock, lambda);
    else frame_block<false>(data + k * FrameBatch::kBlock, lambda);
  }
}

// The energy of four recorded terms at displacement d (dd = |d|²).
template <bool kUntangle>
[[gnu::always_inline]] inline d4 model_block(const double* b, const Vec3& d, double dd, double lambda) {
  using M = FrameBatch;
  const d4 D = field(b, M::kD) + ((field(b, M::kGD) * d[0] + field(b, M::kGD + 1) * d[1]) + field(b, M::kGD + 2) * d[2]);
  const d4 F = (field(b, M::kF) + ((field(b, M::kGF) * d[0] + field(b, M::kGF + 1) * d[1]) + field(b, M::kGF + 2) * d[2])) + field(b, M::kCc) * dd;
  if constexpr (kUntangle) {
    return untangle_term(F, D, field(b, M::kEps), lambda).f;
  } else {
    const d4 constraint = D > kMinFeasibleDet ? splat<d4>(0.0) : splat<d4>(kInf);
    return field(b, M::kConstraint) != 0.0 ? constraint : shape_term(F, D).f;
  }
}

[[gnu::always_inline]] inline void model_body(const double* data, std::size_t blocks, bool untangle, const Vec3& d, double lambda, double* f) {
  const double dd = d.squaredNorm();
  for (std::size_t k = 0; k < blocks; ++k) {
    const double* b = data + k * FrameBatch::kBlock;
    store(f + 4 * k, untangle ? model_block<true>(b, d, dd, lambda) : model_block<false>(b, d, dd, lambda));
  }
}

// The interior frames' coefficients, four frames to a block: [block][corner k][column j][lane],
// zero in a frame's place for a corner it does not use and in the last block's two spare lanes.
constexpr int kInteriorBlocks = (kAllFrames - kFrames + 3) / 4;
// (Built on first use: frame_coefficient()'s table is another file's static.)
const std::array<double, kInteriorBlocks * 8 * 3 * 4>& dense_coef() {
  static const std::array<double, kInteriorBlocks * 8 * 3 * 4> table = [] {
    std::array<double, kInteriorBlocks * 8 * 3 * 4> c{};
    for (int t = kFrames; t < kAllFrames; ++t) {
      const int b = (t - kFrames) / 4, lane = (t - kFrames) % 4;
      for (int k = 0; k < 8; ++k)
        for (int j = 0; j < 3; ++j)
          c[static_cast<std::size_t>(((b * 8 + k) * 3 + j) * 4 + lane)] = frame_coefficient(t, k)[j];
    }
    return c;
  }();
  return table;
}

// interior_frame() for four frames at once: Σ_k d_k c_{t,k}ᵀ entry by entry in k order, then
// scaled. A coefficient that interior_frame() skips (zero) adds ±0 here, which leaves a sum
// that started at +0 as it is, so the same bits.
[[gnu::always_inline]] inline void interior_body(const RelativeCorners& d, double inv_len, Mat3* out, int first) {
  const auto& coef = dense_coef();
  for (int b = first; b < kInteriorBlocks; ++b) {
    d4 a[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) a[i][j] = splat<d4>(0.0);
    for (int k = 0; k < 8; ++k)
      for (int j = 0; j < 3; ++j) {
        const d4 c = load(&coef[static_cast<std::size_t>(((b * 8 + k) * 3 + j) * 4)]);
        for (int i = 0; i < 3; ++i) a[i][j] += d[k][i] * c;
      }
    for (int lane = 0; lane < 4; ++lane) {
      const int f = 4 * b + lane;
      if (f >= kAllFrames - kFrames) break;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) out[f](i, j) = a[i][j][lane] * inv_len;
    }
  }
}

// Determinants and det_gradient()s of up to 28 frames, four at a time, in the orders of
// Eigen's determinant() and of det_gradient()'s expression: the same bits.
[[gnu::always_inline]] inline void lattice_body(LatticeFrames& f, bool gradients) {
  for (int b = 0; b < LatticeFrames::kBlocks; ++b) {
    d4 a[9];
    for (int e = 0; e < 9; ++e) a[e] = lanes(b, f.a[static_cast<std::size_t>(e)]);
    const d4 a0 = a[0], a1 = a[1], a2 = a[2], a3 = a[3], a4 = a[4], a5 = a[5], a6 = a[6], a7 = a[7], a8 = a[8];
    store(&f.det[static_cast<std::size_t>(4 * b)], determinants(a));
    if (!gradients) continue;
    const d4 c0 = lanes(b, f.c[0]), c1 = lanes(b, f.c[1]), c2 = lanes(b, f.c[2]);
    const d4 x[3] = {a4 * a8 - a5 * a7, a5 * a6 - a3 * a8, a3 * a7 - a4 * a6};  // col1 × col2
    const d4 y[3] = {a7 * a2 - a8 * a1, a8 * a0 - a6 * a2, a6 * a1 - a7 * a0};  // col2 × col0
    const d4 z[3] = {a1 * a5 - a2 * a4, a2 * a3 - a0 * a5, a0 * a4 - a1 * a3};  // col0 × col1
    for (int i = 0; i < 3; ++i) store(&f.grad[i][static_cast<std::size_t>(4 * b)], (c0 * x[i] + c1 * y[i]) + c2 * z[i]);
  }
}

// The sum of a hex's eight corner shape terms (frames 0..7 of frame(), the shape objective's
// terms), four corners at a time: each lane the scalar term_value()'s expressions (Eigen's
// orders for squaredNorm() and determinant(), shape_term()), summed in corner order, so the
// same bits. The shape stage evaluates every changed hex's energy after each sweep.
[[gnu::always_inline]] inline double corner_shape_body(const std::array<Vec3, 8>& p, double il) {
  double f[8];
  for (int half = 0; half < 2; ++half) {
    d4 a[9];
    for (int col = 0; col < 3; ++col)
      for (int r = 0; r < 3; ++r) {
        d4 x;
        for (int l = 0; l < 4; ++l) {
          const int t = 4 * half + l;
          x[l] = (p[kCornerNeighbors[static_cast<std::size_t>(t)][static_cast<std::size_t>(col)]][r] - p[t][r]) * il;
        }
        a[r + 3 * col] = x;
      }
    store(f + 4 * half, shape_term(squared_norms(a), determinants(a)).f);
  }
  double e = 0;
  for (double x : f) e += x;
  return e;
}

#if ISOHEX_HAVE_FMV
// AVX2 where the CPU has it (no FMA: the same bits as the baseline's SSE2 pairs).
[[gnu::target("default")]] void frames_kernel(double* data, std::size_t blocks, bool untangle, double lambda) {
  frames_body(data, blocks, untangle, lambda);
}
[[gnu::target("avx2")]] void frames_kernel(double* data, std::size_t blocks, bool untangle, double lambda) {
  frames_body(data, blocks, untangle, lambda);
}
[[gnu::target("default")]] void model_kernel(const double* data, std::size_t blocks, bool untangle, const Vec3& d,
                                             double lambda, double* f) {
  model_body(data, blocks, untangle, d, lambda, f);
}
[[gnu::target("avx2")]] void model_kernel(const double* data, std::size_t blocks, bool untangle, const Vec3& d,
                                          double lambda, double* f) {
  model_body(data, blocks, untangle, d, lambda, f);
}
[[gnu::target("default")]] void interior_kernel(const RelativeCorners& d, double inv_len, Mat3* out, int first) {
  interior_body(d, inv_len, out, first);
}
[[gnu::target("avx2")]] void interior_kernel(const RelativeCorners& d, double inv_len, Mat3* out, int first) {
  interior_body(d, inv_len, out, first);
}
[[gnu::target("default")]] void lattice_kernel(LatticeFrames& f, bool gradients) { lattice_body(f, gradients); }
[[gnu::target("avx2")]] void lattice_kernel(LatticeFrames& f, bool gradients) { lattice_body(f, gradients); }
[[gnu::target("default")]] double corner_shape_kernel(const std::array<Vec3, 8>& p, double il) {
  return corner_shape_body(p, il);
}
[[gnu::target("avx2")]] double corner_shape_kernel(const std::array<Vec3, 8>& p, double il) {
  return corner_shape_body(p, il);
}
#else
double corner_shape_kernel(const std::array<Vec3, 8>& p, double il) { return corner_shape_body(p, il); }
void lattice_kernel(LatticeFrames& f, bool gradients) { lattice_body(f, gradients); }
void interior_kernel(const RelativeCorners& d, double inv_len, Mat3* out, int first) {
  interior_body(d, inv_len, out, first);
}
void frames_kernel(double* data, std::size_t blocks, bool untangle, double lambda) {
  frames_body(data, blocks, untangle, lambda);
}
void model_kernel(const double* data, std::size_t blocks, bool untangle, const Vec3& d, double lambda, double* f) {
  model_body(data, blocks, untangle, d, lambda, f);
}
#endif

// The unused lanes of the last block: a unit frame with no coefficient (finite terms, no NaN).
void pad(FrameBatch& b) {
  for (std::size_t i = b.size; i % 4 != 0; ++i) {
    for (int f = 0; f < FrameBatch::kFields; ++f) b.at(i, f) = 0.0;
    for (int f : {0, 4, 8, int{FrameBatch::kIl}, int{FrameBatch::kEps}, int{FrameBatch::kD}}) b.at(i, f) = 1.0;
    b.at(i, FrameBatch::kF) = 3.0;
  }
}

}  // namespace

double corner_shape_energy(const std::array<Vec3, 8>& p, double inv_len) { return corner_shape_kernel(p, inv_len); }

void FrameBatch::compute(bool untangle, double lambda) {
  pad(*this);
  frames_kernel(data.data(), (size + 3) / 4, untangle, lambda);
}

void TermModels::seal() { pad(terms); }

void LatticeFrames::compute(bool gradients) { lattice_kernel(*this, gradients); }

void interior_frames(const RelativeCorners& d, double inv_len, InteriorFrames& out, bool gauss) {
  // Frames 9..16 are the Gauss points (local_energy.hpp): the first two blocks.
  interior_kernel(d, inv_len, out.data(), gauss ? 0 : 2);
}

double model_energy(const TermModels& model, const Vec3& d, double lambda) {
  const std::size_t n = model.size();
  if (n == 0) return 0;
  thread_local std::vector<double> f;
  const std::size_t blocks = (n + 3) / 4;
  if (f.size() < 4 * blocks) f.resize(4 * blocks);
  model_kernel(model.terms.data.data(), blocks, model.untangle, d, lambda, f.data());
  double e = 0;
  for (std::size_t i = 0; i < n; ++i) {  // in term order: the sum of a term-by-term loop
    e += f[i];
    if (!std::isfinite(e)) return kInf;
  }
  return e;
}

}  // namespace isohex::opt
