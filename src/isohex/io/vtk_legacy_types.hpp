#pragma once
/// \file vtk_legacy_types.hpp
/// \brief Data types, cell types, binary decoding and name decoding of legacy VTK files,
/// shared by the reader and the writer.

#include "isohex/io/big_endian.hpp"
#include "isohex/io/format_support.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace isohex::io::vtk {

inline constexpr int kVoxel = 11;       ///< VTK_VOXEL: a hex with lexicographic corner order
inline constexpr int kHexahedron = 12;  ///< VTK_HEXAHEDRON

/// The value types a legacy file can name.
enum class Scalar { bit, i8, u8, i16, u16, i32, u32, i64, u64, f32, f64, string };

/// The scalar type a data-type token names (case-insensitive), if any.
inline std::optional<Scalar> scalar_named(std::string_view name) {
  struct Entry {
    std::string_view name;
    Scalar scalar;
  };
  static constexpr Entry kTable[] = {
      {"bit", Scalar::bit},
      {"char", Scalar::i8},
      {"signed_char", Scalar::i8},
      {"unsigned_char", Scalar::u8},
      {"short", Scalar::i16},
      {"unsigned_short", Scalar::u16},
      {"int", Scalar::i32},
      {"unsigned_int", Scalar::u32},
      // "long" has the writer's sizeof(long): 8 on the LP64 systems that write such files.
      {"long", Scalar::i64},
      {"unsigned_long", Scalar::u64},
      // VTK writes vtkIdType arrays as 32-bit ints.
      {"vtkidtype", Scalar::i32},
      {"vtktypeint8", Scalar::i8},
      {"vtktypeuint8", Scalar::u8},
      {"vtktypeint16", Scalar::i16},
      {"vtktypeuint16", Scalar::u16},
      {"vtktypeint32", Scalar::i32},
      {"vtktypeuint32", Scalar::u32},
      {"vtktypeint64", Scalar::i64},
      {"vtktypeuint64", Scalar::u64},
      {"vtktypefloat32", Scalar::f32},
      {"vtktypefloat64", Scalar::f64},
      {"float", Scalar::f32},
      {"double", Scalar::f64},
      {"string", Scalar::string},
      {"utf8_string", Scalar::string}};
  for (const Entry& e : kTable)
    if (iequals(name, e.name)) return e.scalar;
  return std::nullopt;
}

/// Bytes per value in binary files (0 for bit and string arrays, which are packed).
inline std::size_t size_of(Scalar s) {
  switch (s) {
    case Scalar::i8:
    case Scalar::u8:
      return 1;
    case Scalar::i16:
    case Scalar::u16:
      return 2;
    case Scalar::i32:
    case Scalar::u32:
    case Scalar::f32:
      return 4;
    case Scalar::i64:
    case Scalar::u64:
    case Scalar::f64:
      return 8;
    case Scalar::bit:
    case Scalar::string:
      return 0;
  }
  return 0;
}

inline bool is_integer(Scalar s) { return s != Scalar::f32 && s != Scalar::f64 && s != Scalar::string; }

/// The name of a VTK cell type, empty for numbers VTK does not define.
inline std::string_view cell_type_name(std::int64_t type) {
  switch (type) {
    case 0:
      return "empty cell";
    case 1:
      return "vertex";
    case 2:
      return "poly-vertex";
    case 3:
      return "line";
    case 4:
      return "poly-line";
    case 5:
      return "triangle";
    case 6:
      return "triangle strip";
    case 7:
      return "polygon";
    case 8:
      return "pixel";
    case 9:
      return "quad";
    case 10:
      return "tetrahedron";
    case 11:
      return "voxel";
    case 12:
      return "hexahedron";
    case 13:
      return "wedge";
    case 14:
      return "pyramid";
    case 15:
      return "pentagonal prism";
    case 16:
      return "hexagonal prism";
    case 21:
      return "quadratic edge";
    case 22:
      return "quadratic triangle";
    case 23:
      return "quadratic quad";
    case 24:
      return "quadratic tetrahedron";
    case 25:
      return "quadratic hexahedron";
    case 26:
      return "quadratic wedge";
    case 27:
      return "quadratic pyramid";
    case 28:
      return "biquadratic quad";
    case 29:
      return "triquadratic hexahedron";
    case 30:
      return "quadratic-linear quad";
    case 31:
      return "quadratic-linear wedge";
    case 32:
      return "biquadratic-quadratic wedge";
    case 33:
      return "biquadratic-quadratic hexahedron";
    case 34:
      return "biquadratic triangle";
    case 35:
      return "cubic line";
    case 36:
      return "quadratic polygon";
    case 37:
      return "triquadratic pyramid";
    case 41:
      return "convex point set";
    case 42:
      return "polyhedron";
    case 51:
      return "parametric curve";
    case 52:
      return "parametric surface";
    case 53:
      return "parametric triangle surface";
    case 54:
      return "parametric quad surface";
    case 55:
      return "parametric tetrahedral region";
    case 56:
      return "parametric hexahedral region";
    case 60:
      return "higher-order edge";
    case 61:
      return "higher-order triangle";
    case 62:
      return "higher-order quad";
    case 63:
      return "higher-order polygon";
    case 64:
      return "higher-order tetrahedron";
    case 65:
      return "higher-order wedge";
    case 66:
      return "higher-order pyramid";
    case 67:
      return "higher-order hexahedron";
    case 68:
      return "Lagrange curve";
    case 69:
      return "Lagrange triangle";
    case 70:
      return "Lagrange quadrilateral";
    case 71:
      return "Lagrange tetrahedron";
    case 72:
      return "Lagrange hexahedron";
    case 73:
      return "Lagrange wedge";
    case 74:
      return "Lagrange pyramid";
    case 75:
      return "Bezier curve";
    case 76:
      return "Bezier triangle";
    case 77:
      return "Bezier quadrilateral";
    case 78:
      return "Bezier tetrahedron";
    case 79:
      return "Bezier hexahedron";
    case 80:
      return "Bezier wedge";
    case 81:
      return "Bezier pyramid";
    default:
      return {};
  }
}

/// Calls f(i, value) for the n big-endian values of type T at p.
template <class T, class F>
void each_be(const unsigned char* p, std::uint64_t n, F& f) {
  for (std::uint64_t i = 0; i < n; ++i) f(i, load_be<T>(p + i * sizeof(T)));
}

/// Decodes n big-endian values of scalar type s (not bit or string) at p: f(i, value).
template <class F>
void decode_binary(Scalar s, const unsigned char* p, std::uint64_t n, F&& f) {
  switch (s) {
    case Scalar::i8:
      each_be<std::int8_t>(p, n, f);
      break;
    case Scalar::u8:
      each_be<std::uint8_t>(p, n, f);
      break;
    case Scalar::i16:
      each_be<std::int16_t>(p, n, f);
      break;
    case Scalar::u16:
      each_be<std::uint16_t>(p, n, f);
      break;
    case Scalar::i32:
      each_be<std::int32_t>(p, n, f);
      break;
    case Scalar::u32:
      each_be<std::uint32_t>(p, n, f);
      break;
    case Scalar::i64:
      each_be<std::int64_t>(p, n, f);
      break;
    case Scalar::u64:
      each_be<std::uint64_t>(p, n, f);
      break;
    case Scalar::f32:
      each_be<float>(p, n, f);
      break;
    case Scalar::f64:
      each_be<double>(p, n, f);
      break;
    case Scalar::bit:
    case Scalar::string:
      break;  // handled by the callers
  }
}

/// The value of hexadecimal digit c, -1 if it is none.
inline int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

/// Array names are %XX-encoded in legacy files ("Nodal%20Stress").
inline std::string decode_name(std::string_view s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && hex_digit(s[i + 1]) >= 0 && hex_digit(s[i + 2]) >= 0) {
      out += static_cast<char>(hex_digit(s[i + 1]) * 16 + hex_digit(s[i + 2]));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

}  // namespace isohex::io::vtk
