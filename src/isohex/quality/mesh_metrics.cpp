// Metrics over whole meshes: oneTBB over blocks of hexes, and a batched scaled-Jacobian kernel.
//
// The batched kernel computes the same IEEE operations as scaled_jacobian() in the same order
// (Verdict's), only on kLanes (8) hexes side by side in structure-of-arrays form, so that the
// compiler turns every step into packed SIMD instructions. Packed and scalar IEEE arithmetic
// round identically, the library is built with -ffp-contract=off (no FMA), and min/max are
// written as the `a < b ? a : b` selects Verdict uses, so the fast path returns the very bits
// of the scalar one (tested). The kernel is compiled once per instruction set (AVX-512, AVX2,
// baseline SSE2) and GCC's function multiversioning picks one when the program loads, so the
// binary stays portable and no -march flag is needed.

#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/verdict_vector.hpp"
#include "isohex/internal/multiversion.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstddef>

#if ISOHEX_HAVE_FMV
#include <immintrin.h>
#endif

namespace isohex {

namespace {

using detail::kDblMax;

/// Hexes per batch: one AVX-512 register of doubles, two AVX2 ones, four SSE2 ones.
constexpr int kLanes = 8;
/// Hexes per TBB task: large enough to hide scheduling, small enough to balance 2+ cores.
constexpr std::size_t kGrain = 4096;
// The kernel reads the coordinates as a flat array of doubles.
static_assert(sizeof(Vec3) == 3 * sizeof(double), "Eigen::Vector3d must be unpadded");

/// One triple of one lane: Verdict's determinant and the product of the squared lengths
/// (whose square root divides it). `shortest` keeps the smallest squared length seen: Verdict
/// returns 1e30 as soon as one is <= VERDICT_DBL_MIN, i.e. iff the smallest is (a NaN length
/// fails that test in Verdict and never enters the minimum here).
[[gnu::always_inline]] inline void sj_triple(double ax, double ay, double az, double bx, double by,
                                             double bz, double cx, double cy, double cz,
                                             double& jac, double& prod, double& shortest) {
  jac = ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx);
  const double l1 = ax * ax + ay * ay + az * az;
  const double l2 = bx * bx + by * by + bz * bz;
  const double l3 = cx * cx + cy * cy + cz * cz;
  shortest = l1 < shortest ? l1 : shortest;
  shortest = l2 < shortest ? l2 : shortest;
  shortest = l3 < shortest ? l3 : shortest;
  prod = l1 * l2 * l3;
}

/// In-place square roots of the kLanes doubles of `v` (64-byte aligned), one policy per
/// instruction set. std::sqrt may set errno, so GCC keeps a scalar call behind each one and
/// will not vectorise a loop that contains it; the packed instructions are the same correctly
/// rounded IEEE square root.
#if ISOHEX_HAVE_FMV
struct SqrtSse2 {
  static void lanes(double* v) {
    for (int i = 0; i < kLanes; i += 2) _mm_store_pd(v + i, _mm_sqrt_pd(_mm_load_pd(v + i)));
  }
};
struct SqrtAvx2 {
  // 256-bit: as fast per element as 512-bit on current cores, and usable by both wide kernels.
  [[gnu::target("avx2")]] static void lanes(double* v) {
    for (int i = 0; i < kLanes; i += 4) _mm256_store_pd(v + i, _mm256_sqrt_pd(_mm256_load_pd(v + i)));
  }
};
#else
struct SqrtScalar {
  static void lanes(double* v) {
    for (int i = 0; i < kLanes; ++i) v[i] = std::sqrt(v[i]);
  }
};
#endif

/// One principal axis at the centre of one lane, summed pairwise in Verdict's order.
[[gnu::always_inline]] inline double sj_axis(const double (&q)[8][kLanes], int l, int a0, int a1,
                                             int b0, int b1, int c0, int c1, int d0, int d1) {
  double v = q[a0][l] - q[a1][l];
  v += q[b0][l] - q[b1][l];
  v += q[c0][l] - q[c1][l];
  v += q[d0][l] - q[d1][l];
  return v;
}

/// Corner K of every lane: its three edge vectors (kCornerNeighbors order) as one triple.
template <int K>
[[gnu::always_inline]] inline void sj_corner(const double (&qx)[8][kLanes], const double (&qy)[8][kLanes],
                                             const double (&qz)[8][kLanes], double (&jac)[kLanes],
                                             double (&prod)[kLanes], double (&shortest)[kLanes]) {
  constexpr int a = kCornerNeighbors[K][0], b = kCornerNeighbors[K][1], c = kCornerNeighbors[K][2];
  for (int l = 0; l < kLanes; ++l) {
    sj_triple(qx[a][l] - qx[K][l], qy[a][l] - qy[K][l], qz[a][l] - qz[K][l],  //
              qx[b][l] - qx[K][l], qy[b][l] - qy[K][l], qz[b][l] - qz[K][l],  //
              qx[c][l] - qx[K][l], qy[c][l] - qy[K][l], qz[c][l] - qz[K][l],  //
              jac[l], prod[l], shortest[l]);
  }
}

/// Scaled Jacobians of hexes [begin, end). Each batch gathers kLanes hexes' corners into
/// structure-of-arrays buffers; every step is then an innermost loop over the lanes with no
/// data-dependent control flow, which the compiler turns into packed instructions of the
/// instruction set of the function it is inlined into (see sj_range below).
template <class Sqrt>
[[gnu::always_inline]] inline void sj_kernel(const double* pts, const Hex* hexes, std::size_t begin,
                                             std::size_t end, double* out) {
  alignas(64) double px[8][kLanes], py[8][kLanes], pz[8][kLanes];
  alignas(64) double qx[8][kLanes], qy[8][kLanes], qz[8][kLanes];
  alignas(64) double lox[kLanes], loy[kLanes], loz[kLanes], hix[kLanes], hiy[kLanes], hiz[kLanes];
  alignas(64) double cx[kLanes], cy[kLanes], cz[kLanes], len[kLanes];
  alignas(64) double jac[9][kLanes], prod[9][kLanes];  // centre, then corners 0..7
  alignas(64) double shortest[kLanes];  // smallest squared edge-vector length
  for (std::size_t h0 = begin; h0 < end; h0 += kLanes) {
    const std::size_t n = end - h0 < kLanes ? end - h0 : kLanes;
    for (int l = 0; l < kLanes; ++l) {
      // Spare lanes of the last batch repeat its first hex; their results are dropped.
      const Hex& hx = hexes[h0 + (static_cast<std::size_t>(l) < n ? l : 0)];
      for (int i = 0; i < 8; ++i) {
        const double* p = pts + 3 * static_cast<std::size_t>(hx[i]);
        px[i][l] = p[0];
        py[i][l] = p[1];
        pz[i][l] = p[2];
      }
    }
    // Verdict's elem_scaling(): bounding box and centroid (summed from 0.0, in node order).
    for (int l = 0; l < kLanes; ++l) {
      lox[l] = loy[l] = loz[l] = kDblMax;
      hix[l] = hiy[l] = hiz[l] = -kDblMax;
      cx[l] = cy[l] = cz[l] = 0.0;
    }
    for (int i = 0; i < 8; ++i) {
      for (int l = 0; l < kLanes; ++l) {
        const double x = px[i][l], y = py[i][l], z = pz[i][l];
        lox[l] = x < lox[l] ? x : lox[l];
        loy[l] = y < loy[l] ? y : loy[l];
        loz[l] = z < loz[l] ? z : loz[l];
        hix[l] = x > hix[l] ? x : hix[l];
        hiy[l] = y > hiy[l] ? y : hiy[l];
        hiz[l] = z > hiz[l] ? z : hiz[l];
        cx[l] += x;
        cy[l] += y;
        cz[l] += z;
      }
    }
    for (int l = 0; l < kLanes; ++l) {
      const double dx = hix[l] - lox[l], dy = hiy[l] - loy[l], dz = hiz[l] - loz[l];
      len[l] = dx * dx + dy * dy + dz * dz;
    }
    Sqrt::lanes(len);
    for (int l = 0; l < kLanes; ++l) {
      const bool tiny = len[l] < kVerdictDblMin;
      cx[l] = tiny ? 0.0 : cx[l] / 8.0;
      cy[l] = tiny ? 0.0 : cy[l] / 8.0;
      cz[l] = tiny ? 0.0 : cz[l] / 8.0;
      len[l] = tiny ? 1.0 : len[l];
      shortest[l] = kDblMax;
    }
    for (int i = 0; i < 8; ++i) {
      for (int l = 0; l < kLanes; ++l) {
        qx[i][l] = (px[i][l] - cx[l]) / len[l];
        qy[i][l] = (py[i][l] - cy[l]) / len[l];
        qz[i][l] = (pz[i][l] - cz[l]) / len[l];
      }
    }
    // Centre: the three principal axes.
    for (int l = 0; l < kLanes; ++l) {
      sj_triple(sj_axis(qx, l, 1, 0, 2, 3, 5, 4, 6, 7), sj_axis(qy, l, 1, 0, 2, 3, 5, 4, 6, 7),
                sj_axis(qz, l, 1, 0, 2, 3, 5, 4, 6, 7), sj_axis(qx, l, 2, 0, 3, 1, 6, 4, 7, 5),
                sj_axis(qy, l, 2, 0, 3, 1, 6, 4, 7, 5), sj_axis(qz, l, 2, 0, 3, 1, 6, 4, 7, 5),
                sj_axis(qx, l, 4, 0, 5, 1, 6, 2, 7, 3), sj_axis(qy, l, 4, 0, 5, 1, 6, 2, 7, 3),
                sj_axis(qz, l, 4, 0, 5, 1, 6, 2, 7, 3), jac[0][l], prod[0][l], shortest[l]);
    }
    Sqrt::lanes(prod[0]);
    // The eight corners, unrolled at compile time so that every index is a constant.
    sj_corner<0>(qx, qy, qz, jac[1], prod[1], shortest);
    Sqrt::lanes(prod[1]);
    sj_corner<1>(qx, qy, qz, jac[2], prod[2], shortest);
    Sqrt::lanes(prod[2]);
    sj_corner<2>(qx, qy, qz, jac[3], prod[3], shortest);
    Sqrt::lanes(prod[3]);
    sj_corner<3>(qx, qy, qz, jac[4], prod[4], shortest);
    Sqrt::lanes(prod[4]);
    sj_corner<4>(qx, qy, qz, jac[5], prod[5], shortest);
    Sqrt::lanes(prod[5]);
    sj_corner<5>(qx, qy, qz, jac[6], prod[6], shortest);
    Sqrt::lanes(prod[6]);
    sj_corner<6>(qx, qy, qz, jac[7], prod[7], shortest);
    Sqrt::lanes(prod[7]);
    sj_corner<7>(qx, qy, qz, jac[8], prod[8], shortest);
    Sqrt::lanes(prod[8]);
    alignas(64) double res[kLanes];
    for (int l = 0; l < kLanes; ++l) {
      // Running minimum in Verdict's visiting order (it decides which signed zero survives).
      double m = kDblMax;
      for (int t = 0; t < 9; ++t) {
        const double v = jac[t][l] / prod[t][l];
        m = v < m ? v : m;
      }
      // Verdict's clamp (m is never NaN: it only takes values that compare below it).
      const double clamped = m > 0 ? (m < kDblMax ? m : kDblMax) : (m > -kDblMax ? m : -kDblMax);
      res[l] = shortest[l] <= kVerdictDblMin ? kDblMax : clamped;
    }
    for (std::size_t l = 0; l < n; ++l) out[h0 + l] = res[l];
  }
}

#if ISOHEX_HAVE_FMV
// The kernel for each instruction set; the dynamic loader binds sj_range to the best one the
// CPU runs. AVX-512 (double-pumped on AMD Zen 4) gains little over AVX2 for this kernel, but
// costs nothing where it exists.
[[gnu::target("default")]] void sj_range(const double* pts, const Hex* hexes, std::size_t begin,
                                         std::size_t end, double* out) {
  sj_kernel<SqrtSse2>(pts, hexes, begin, end, out);
}
[[gnu::target("avx2")]] void sj_range(const double* pts, const Hex* hexes, std::size_t begin,
                                      std::size_t end, double* out) {
  sj_kernel<SqrtAvx2>(pts, hexes, begin, end, out);
}
[[gnu::target("avx512f")]] void sj_range(const double* pts, const Hex* hexes, std::size_t begin,
                                         std::size_t end, double* out) {
  sj_kernel<SqrtAvx2>(pts, hexes, begin, end, out);
}
#else
void sj_range(const double* pts, const Hex* hexes, std::size_t begin, std::size_t end, double* out) {
  sj_kernel<SqrtScalar>(pts, hexes, begin, end, out);
}
#endif

// The batch kernel over hexes[0, n) of mesh's points, in parallel blocks.
std::vector<double> scaled_jacobians_of(const HexMesh& mesh, const Hex* hexes, std::size_t n) {
  std::vector<double> out(n);
  if (n == 0) return out;
  const double* pts = mesh.points.empty() ? nullptr : mesh.points.front().data();
  double* dst = out.data();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kGrain),
                    [=](const tbb::blocked_range<std::size_t>& r) { sj_range(pts, hexes, r.begin(), r.end(), dst); });
  return out;
}

}  // namespace

std::vector<double> scaled_jacobians(const HexMesh& mesh) {
  return scaled_jacobians_of(mesh, mesh.hexes.data(), mesh.hexes.size());
}

std::vector<double> scaled_jacobians(const HexMesh& mesh, const std::vector<Index>& ids) {
  std::vector<Hex> picked(ids.size());  // the kernel reads hexes side by side
  for (std::size_t i = 0; i < ids.size(); ++i) picked[i] = mesh.hexes[static_cast<std::size_t>(ids[i])];
  return scaled_jacobians_of(mesh, picked.data(), picked.size());
}

std::vector<double> hex_metric(const HexMesh& mesh, HexMetric m) {
  if (m == HexMetric::scaled_jacobian) return scaled_jacobians(mesh);
  std::vector<double> out(mesh.hexes.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, out.size(), kGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t h = r.begin(); h != r.end(); ++h)
                        out[h] = hex_metric(m, mesh.corners(static_cast<Index>(h)));
                    });
  return out;
}

}  // namespace isohex
