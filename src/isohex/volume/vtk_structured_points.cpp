// Legacy VTK STRUCTURED_POINTS volumes (.vtk), ASCII or BINARY (always big-endian):
// DIMENSIONS, SPACING or its old name ASPECT_RATIO, ORIGIN, then POINT_DATA with one
// SCALARS array, or COLOR_SCALARS with one component (what VTK writes for unsigned char
// images: bytes in binary files, byte/255 in ASCII ones). As in VTK's reader, binary values start right after the
// newline that ends the LOOKUP_TABLE line (or the SCALARS line when there is no lookup table).
#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/format_support.hpp"
#include "isohex/io/text_scanner.hpp"
#include "isohex/io/vtk_legacy_types.hpp"
#include "isohex/volume/decode.hpp"
#include "isohex/volume/formats.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace isohex::volume_detail {

namespace {

namespace fs = std::filesystem;
using io::iequals;

struct LegacyHeader {
  std::array<std::int64_t, 3> dims{};
  Vec3 spacing = Vec3::Ones(), origin = Vec3::Zero();
  ScalarType type = ScalarType::f32;
  bool binary = false;
  bool color = false;  // COLOR_SCALARS: u8, stored as byte/255 in ASCII files
  std::size_t data_offset = 0;
  std::size_t data_line = 1;
};

std::optional<ScalarType> to_scalar_type(io::vtk::Scalar s) {
  using io::vtk::Scalar;
  switch (s) {
    case Scalar::i8:
      return ScalarType::i8;
    case Scalar::u8:
      return ScalarType::u8;
    case Scalar::i16:
      return ScalarType::i16;
    case Scalar::u16:
      return ScalarType::u16;
    case Scalar::i32:
      return ScalarType::i32;
    case Scalar::u32:
      return ScalarType::u32;
    case Scalar::f32:
      return ScalarType::f32;
    case Scalar::f64:
      return ScalarType::f64;
    default:
      return std::nullopt;
  }
}

LegacyHeader parse(const fs::path& file, std::string_view text) {
  io::TextScanner sc(text, file);
  LegacyHeader h;
  const std::string_view magic = sc.rest_of_line();
  if (!io::istarts_with(magic, "# vtk DataFile"))
    sc.fail("not a legacy VTK file: the first line should be '# vtk DataFile Version x.x'");
  sc.rest_of_line();  // the title
  const std::string_view mode = sc.expect("ASCII or BINARY");
  if (iequals(mode, "BINARY"))
    h.binary = true;
  else if (!iequals(mode, "ASCII"))
    sc.fail(fmt::format("expected ASCII or BINARY, found '{}'", io::printable(mode)));
  if (!iequals(sc.expect("DATASET"), "DATASET")) sc.fail("expected DATASET");
  const std::string_view kind = sc.expect("the dataset type");
  if (!iequals(kind, "STRUCTURED_POINTS"))
    sc.fail(
        fmt::format("isohex reads volumes from STRUCTURED_POINTS datasets; this file holds {}", io::printable(kind)));
  bool dims_seen = false;
  while (true) {
    const std::string_view key = sc.expect("POINT_DATA");
    if (iequals(key, "DIMENSIONS")) {
      for (auto& d : h.dims) d = sc.next_int("a DIMENSIONS value");
      dims_seen = true;
    } else if (iequals(key, "SPACING") || iequals(key, "ASPECT_RATIO")) {
      for (int a = 0; a < 3; ++a) h.spacing[a] = sc.next_double("a SPACING value");
      check_vector(file, fmt::format("line {}: {}", sc.line(), io::printable(key)), h.spacing, true);
    } else if (iequals(key, "ORIGIN")) {
      for (int a = 0; a < 3; ++a) h.origin[a] = sc.next_double("an ORIGIN value");
    } else if (iequals(key, "POINT_DATA")) {
      break;
    } else {
      sc.fail(fmt::format("unexpected '{}' (expected DIMENSIONS, SPACING, ASPECT_RATIO, ORIGIN or POINT_DATA)",
                          io::printable(key)));
    }
  }
  if (!dims_seen) sc.fail("POINT_DATA before DIMENSIONS");
  const std::int64_t n = sc.next_int("the POINT_DATA count", 0);
  // The product cannot overflow here: each factor is checked against INT32_MAX first.
  bool sane = true;
  for (auto d : h.dims) sane = sane && d > 0 && d <= INT32_MAX;
  if (sane && n != h.dims[0] * h.dims[1] * h.dims[2])
    sc.fail(fmt::format("POINT_DATA {} does not match DIMENSIONS {} x {} x {} = {}", n, h.dims[0], h.dims[1], h.dims[2],
                        h.dims[0] * h.dims[1] * h.dims[2]));
  const std::string_view attr = sc.expect("SCALARS");
  if (iequals(attr, "COLOR_SCALARS")) {
    sc.expect("the COLOR_SCALARS name");
    const std::int64_t components = sc.next_int("the COLOR_SCALARS component count");
    if (components != 1)
      sc.fail(fmt::format("COLOR_SCALARS with {} components: isohex reads one (a grey-level image)", components));
    sc.rest_of_line();
    h.type = ScalarType::u8;
    h.color = true;
    h.data_offset = sc.offset();
    h.data_line = sc.line();
    return h;
  }
  if (!iequals(attr, "SCALARS"))
    sc.fail(fmt::format("isohex reads the SCALARS or COLOR_SCALARS array of POINT_DATA; found '{}' first",
                        io::printable(attr)));
  sc.expect("the SCALARS name");
  const std::string_view type_name = sc.expect("the SCALARS data type");
  const auto vtk_type = io::vtk::scalar_named(type_name);
  if (!vtk_type) sc.fail(fmt::format("SCALARS: unknown data type '{}'", io::printable(type_name)));
  const auto type = to_scalar_type(*vtk_type);
  if (!type)
    sc.fail(
        fmt::format("SCALARS: data type '{}' is not supported (isohex reads 8- to 32-bit integers, float and "
                    "double)",
                    io::printable(type_name)));
  h.type = *type;
  // An optional component count, then the end of the line.
  const std::string_view rest = trim(sc.rest_of_line());
  if (!rest.empty() && rest != "1")
    fail(file, fmt::format("line {}", sc.line() - 1),
         fmt::format("SCALARS with '{}' components: isohex reads one", io::printable(rest)));
  const std::size_t after_scalars = sc.offset();
  const std::size_t scalars_line = sc.line();
  // Binary values may begin with whitespace bytes, so only ASCII files skip blanks here.
  if (!h.binary) sc.skip_space();
  if (io::istarts_with(text.substr(sc.offset()), "LOOKUP_TABLE")) {
    sc.next();
    sc.expect("the LOOKUP_TABLE name");
    sc.rest_of_line();
    h.data_offset = sc.offset();
    h.data_line = sc.line();
  } else {
    h.data_offset = after_scalars;
    h.data_line = scalars_line;
  }
  return h;
}

}  // namespace

Volume read_vtk_structured_points(const fs::path& file, const VolumeReadOptions& options) {
  const LegacyHeader h = parse_header(file, [&](std::string_view text, bool) { return parse(file, text); });
  const std::size_t count = check_dims(file, "DIMENSIONS", h.dims, options);
  if (h.binary) {
    const std::size_t bytes = count * scalar_type_size(h.type);
    const std::size_t size = size_of_file(file);
    if (size < h.data_offset || size - h.data_offset < bytes)
      fail(file, fmt::format("line {} (byte {})", h.data_line, h.data_offset),
           fmt::format("binary SCALARS need {} bytes for {} values of {}, but only {} follow (truncated, or the "
                       "header lies)",
                       bytes, count, scalar_type_name(h.type), size > h.data_offset ? size - h.data_offset : 0));
  }
  Volume v = allocate_volume(file, "DIMENSIONS", h.dims, h.type, options);
  v.spacing = h.spacing;
  v.origin = h.origin;
  if (h.binary) {
    FileSource src(file, h.data_offset);
    read_samples(src, h.type, /*big_endian=*/true, v, file, "binary SCALARS");
  } else {
    const std::string text = io::read_file(file);
    io::TextScanner sc(text, file, h.data_offset);
    if (h.color) {  // values in [0, 1] standing for bytes, rounded back as VTK's reader does
      v.source_type = ScalarType::f32;
      read_ascii_samples(sc, v, "COLOR_SCALARS");
      for (float& x : v.values) x = std::floor(std::clamp(x, 0.0f, 1.0f) * 255.0f + 0.5f);
      v.source_type = ScalarType::u8;
    } else {
      read_ascii_samples(sc, v, "SCALARS");
    }
  }
  return v;
}

}  // namespace isohex::volume_detail
