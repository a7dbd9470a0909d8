#pragma once
/// \file frame_terms.hpp
/// \brief Internal to optimize/: one frame's energy term and its scalar derivatives, written
/// once for a double and for four frames at a time (a GCC/Clang vector of four doubles).
///
/// A lane of the vector form performs the very operations of the scalar form in the same order
/// (no fused multiply-add: the library builds with -ffp-contract=off), so both give the same
/// bits; the vertex energies batch their frames through the vector form
/// (frame_batch.cpp) and the whole-hex energies stay scalar.

#include "isohex/optimize/local_energy.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

// A vector argument changes the ABI between instruction sets: every function taking one is
// always inlined into the kernel of one instruction set, so no such call exists.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace isohex::opt {

using d4 = double __attribute__((vector_size(32)));
using u4 = std::uint64_t __attribute__((vector_size(32)));
using m4 = std::int64_t __attribute__((vector_size(32)));  ///< a comparison of d4s

template <class T>
[[gnu::always_inline]] inline T splat(double x) {
  if constexpr (std::is_same_v<T, double>) return x;
  else return d4{x, x, x, x};
}

[[gnu::always_inline]] inline double sqrt_of(double x) { return std::sqrt(x); }
[[gnu::always_inline]] inline d4 sqrt_of(d4 x) {
#if defined(__SSE2__)
  __m128d lo, hi;
  std::memcpy(&lo, &x, 16);
  std::memcpy(&hi, reinterpret_cast<const char*>(&x) + 16, 16);
  lo = _mm_sqrt_pd(lo), hi = _mm_sqrt_pd(hi);  // correctly rounded, as std::sqrt
  d4 r;
  std::memcpy(&r, &lo, 16);
  std::memcpy(reinterpret_cast<char*>(&r) + 16, &hi, 16);
  return r;
#else
  for (int l = 0; l < 4; ++l) x[l] = std::sqrt(x[l]);
  return x;
#endif
}

/// inverse_cbrt() lane by lane: the same start from the bits and the same four Newton steps.
[[gnu::always_inline]] inline d4 inverse_cbrt(d4 x) {
  u4 bits;
  std::memcpy(&bits, &x, sizeof bits);
  const u4 exponent = (bits >> 52) & 0x7ff;
  const m4 special = (exponent == 0) | (exponent == 0x7ff) | ((bits >> 63) != 0);
  bits = 0x553F0A3D70A3D70AULL - bits / 3;
  d4 y;
  std::memcpy(&y, &bits, sizeof y);
  for (int i = 0; i < 4; ++i) y = y * (4.0 - ((x * y) * y) * y) * (1.0 / 3.0);
  for (int l = 0; l < 4; ++l)
    if (special[l]) y[l] = 1 / std::cbrt(x[l]);
  return y;
}

/// The scalar derivatives of one frame's energy f(F, D), F = |A|², D = det A.
template <class T>
struct TermValue {
  T f, fF, fD, fFD, fDD;
};

/// Regularised energy (ε > 0): finite for every D, so the untangler may cross inverted states.
template <class T>
[[gnu::always_inline]] inline TermValue<T> untangle_term(T F, T D, T eps, double lambda) {
  const T s = sqrt_of(eps * eps + D * D);
  // (D + s)/2 cancels for D << 0; the same value as ε²/(2(s − D)) there.
  const T chi = D >= 0.0 ? 0.5 * (D + s) : eps * eps / (2.0 * (s - D));
  const T chi1 = chi / s;                        // dχ/dD
  const T chi2 = eps * eps / (2.0 * s * s * s);  // d²χ/dD²
  const T y = inverse_cbrt(chi), y3 = y * y * y;
  const T c23 = y * y, c53 = c23 * y3, c83 = c53 * y3;  // χ^(−2/3), χ^(−5/3), χ^(−8/3)
  const T q = D * D + 1.0;
  TermValue<T> r;
  r.f = F * c23 / 3.0 + lambda * q / chi;
  r.fF = c23 / 3.0;
  r.fFD = -(2.0 / 9.0) * c53 * chi1;
  r.fD = F * r.fFD + lambda * (2.0 * D / chi - q * chi1 / (chi * chi));
  r.fDD = F / 3.0 * ((10.0 / 9.0) * c83 * chi1 * chi1 - (2.0 / 3.0) * c53 * chi2) +
          lambda * (2.0 / chi - 4.0 * D * chi1 / (chi * chi) + 2.0 * q * chi1 * chi1 / (chi * chi * chi) -
                    q * chi2 / (chi * chi));
  return r;
}

/// Knupp's inverse mean ratio F / (3 D^{2/3}); a barrier: +inf (and no derivatives) unless D
/// is safely positive.
template <class T>
[[gnu::always_inline]] inline TermValue<T> shape_term(T F, T D) {
  const auto valid = D > kMinFeasibleDet;
  const T zero = splat<T>(0.0);
  const T y = inverse_cbrt(valid ? D : splat<T>(1.0)), y3 = y * y * y;
  const T c23 = y * y, c53 = c23 * y3, c83 = c53 * y3;  // D^(−2/3), D^(−5/3), D^(−8/3)
  const T fFD = -(2.0 / 9.0) * c53;
  TermValue<T> r;
  r.f = valid ? F * c23 / 3.0 : splat<T>(std::numeric_limits<double>::infinity());
  r.fF = valid ? c23 / 3.0 : zero;
  r.fFD = valid ? fFD : zero;
  r.fD = valid ? F * fFD : zero;
  r.fDD = valid ? F * (10.0 / 27.0) * c83 : zero;
  return r;
}

}  // namespace isohex::opt
