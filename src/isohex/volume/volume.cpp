#include "isohex/volume/volume.hpp"

#include <array>
#include <cmath>

namespace isohex {

namespace {

struct TypeInfo {
  std::string_view name;
  std::size_t size;
  double lo, hi;  // integer range; unused for the float types
};

constexpr std::array<TypeInfo, 8> kTypes = {{{"u8", 1, 0, 255},
                                             {"i8", 1, -128, 127},
                                             {"u16", 2, 0, 65535},
                                             {"i16", 2, -32768, 32767},
                                             {"u32", 4, 0, 4294967295.0},
                                             {"i32", 4, -2147483648.0, 2147483647.0},
                                             {"f32", 4, 0, 0},
                                             {"f64", 8, 0, 0}}};

const TypeInfo& info(ScalarType t) { return kTypes[static_cast<std::size_t>(t)]; }

}  // namespace

std::string_view scalar_type_name(ScalarType t) { return info(t).name; }

std::optional<ScalarType> scalar_type_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kTypes.size(); ++i)
    if (kTypes[i].name == name) return static_cast<ScalarType>(i);
  return std::nullopt;
}

std::size_t scalar_type_size(ScalarType t) { return info(t).size; }

bool scalar_type_is_integer(ScalarType t) { return t != ScalarType::f32 && t != ScalarType::f64; }

bool scalar_type_holds(ScalarType t, float value) {
  if (!scalar_type_is_integer(t)) return true;
  const double v = value;  // NaN fails both comparisons below
  return v >= info(t).lo && v <= info(t).hi && v == std::trunc(v);
}

}  // namespace isohex
