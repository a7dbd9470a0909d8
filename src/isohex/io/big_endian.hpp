#pragma once
/// \file big_endian.hpp
/// \brief Loading and storing big-endian numbers (legacy VTK binary is always big-endian).

#include <bit>
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
