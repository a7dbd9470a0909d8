#pragma once
/// \file volume.hpp
/// \brief A scalar field sampled on a regular grid: what every mesher input becomes.
///
/// Scans, molecular density maps and sampled implicit shapes all load into one Volume:
/// dimensions, spacing, origin and float values with x varying fastest, then y, then z.
/// The grid point (i, j, k) sits at origin + (i·sx, j·sy, k·sz) in world coordinates.

#include "isohex/mesh/hex_mesh.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace isohex {

/// The element type a volume file stored (values are kept as float either way).
enum class ScalarType : std::uint8_t { u8, i8, u16, i16, u32, i32, f32, f64 };

/// "u8", "i16", "f32", ...
std::string_view scalar_type_name(ScalarType t);
/// The type named "u8", "i16", "f32", ... (the names scalar_type_name gives), if any.
std::optional<ScalarType> scalar_type_from_name(std::string_view name);
/// Bytes per stored value: 1, 2, 4 or 8.
std::size_t scalar_type_size(ScalarType t);
/// True for the six integer types.
bool scalar_type_is_integer(ScalarType t);
/// True if `value` is stored exactly by `t` (an integer in range for the integer types; any
/// float for f32 and f64), so that writing it as `t` and reading it back loses nothing.
bool scalar_type_holds(ScalarType t, float value);

/// A regular scalar grid.
struct Volume {
  std::array<Index, 3> dims{0, 0, 0};  ///< grid points along x, y, z
  Vec3 spacing{1, 1, 1};               ///< distance between grid points along x, y, z (> 0)
  Vec3 origin{0, 0, 0};                ///< world position of grid point (0, 0, 0)
  std::vector<float> values;           ///< dims[0]·dims[1]·dims[2] values, x fastest
  ScalarType source_type = ScalarType::f32;

  [[nodiscard]] std::size_t size() const {
    return static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1]) * static_cast<std::size_t>(dims[2]);
  }
  [[nodiscard]] std::size_t index(Index i, Index j, Index k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(dims[0]) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(dims[1]) * k);
  }
  [[nodiscard]] float at(Index i, Index j, Index k) const { return values[index(i, j, k)]; }
  [[nodiscard]] float& at(Index i, Index j, Index k) { return values[index(i, j, k)]; }
  /// World position of grid point (i, j, k).
  [[nodiscard]] Vec3 point(Index i, Index j, Index k) const {
    return origin + Vec3(i * spacing.x(), j * spacing.y(), k * spacing.z());
  }
  /// World position of the last grid point (the far corner of the bounding box).
  [[nodiscard]] Vec3 max_corner() const { return point(dims[0] - 1, dims[1] - 1, dims[2] - 1); }
};

}  // namespace isohex
