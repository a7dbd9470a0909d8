#pragma once
/// \file big_endian.hpp
/// \brief Loading and storing numbers in a byte order other than the host's (legacy VTK
/// binary is always big-endian; NRRD, NIfTI and raw volumes may be either).

#include <algorithm>
#include <bit>
#include <cstring>
#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace isohex::io {

namespace detail {
template <std::size_t N>
struct UnsignedOfSize;
template <>
struct UnsignedOfSize<1> {
  using type = std::uint8_t;
};
template <>
struct UnsignedOfSize<2> {
  using type = std::uint16_t;
};
template <>
struct UnsignedOfSize<4> {
  using type = std::uint32_t;
};
template <>
struct UnsignedOfSize<8> {
  using type = std::uint64_t;
};
}  // namespace detail

/// The value of type T stored big-endian at `p` (no alignment needed).
template <class T>
T load_be(const unsigned char* p) {
  static_assert(std::is_trivially_copyable_v<T>);
  using U = typename detail::UnsignedOfSize<sizeof(T)>::type;
  // Byte by byte, so the compiler emits a plain load + bswap whatever the host order.
  std::uint64_t u = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) u = (u << 8) | p[i];
  return std::bit_cast<T>(static_cast<U>(u));
}

/// The value of type T stored at `p` (no alignment needed), its bytes reversed if `swap`.
template <class T>
T load_swapped(const unsigned char* p, bool swap) {
  static_assert(std::is_trivially_copyable_v<T>);
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (swap) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

/// Stores `value` big-endian at `p` (sizeof(T) bytes).
template <class T>
void store_be(unsigned char* p, T value) {
  static_assert(std::is_trivially_copyable_v<T>);
  using U = typename detail::UnsignedOfSize<sizeof(T)>::type;
  std::uint64_t u = std::bit_cast<U>(value);
  for (std::size_t i = sizeof(T); i-- > 0;) {
    p[i] = static_cast<unsigned char>(u & 0xffu);
    u >>= 8;
  }
}

}  // namespace isohex::io
