// read_volume / write_volume: the choice of format by extension, the raw reader, and the
// pieces both writers share.
#include "isohex/volume/volume_io.hpp"

#include "isohex/error.hpp"
#include "isohex/volume/decode.hpp"
#include "isohex/volume/formats.hpp"

#include <fmt/format.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <ostream>
#include <vector>

namespace isohex {

namespace fs = std::filesystem;
using namespace volume_detail;

namespace {

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

template <class T>
void write_typed(std::ostream& out, const std::vector<float>& values) {
  constexpr std::size_t kChunk = std::size_t{1} << 16;
  const bool swap = sizeof(T) > 1 && std::endian::native == std::endian::big;
  std::vector<unsigned char> buf(std::min(values.size(), kChunk) * sizeof(T));
  for (std::size_t first = 0; first < values.size(); first += kChunk) {
    const std::size_t n = std::min(kChunk, values.size() - first);
    for (std::size_t i = 0; i < n; ++i) {
      const T v = static_cast<T>(values[first + i]);
      unsigned char* p = buf.data() + i * sizeof(T);
      std::memcpy(p, &v, sizeof(T));
      if (swap) std::reverse(p, p + sizeof(T));
    }
    out.write(reinterpret_cast<const char*>(buf.data()), static_cast<std::streamsize>(n * sizeof(T)));
  }
}

}  // namespace

namespace volume_detail {

Volume read_raw(const fs::path& file, const RawLayout& layout, const VolumeReadOptions& options) {
  constexpr std::string_view field = "raw layout";
  const std::size_t count =
      check_dims(file, "raw layout dims", {layout.dims[0], layout.dims[1], layout.dims[2]}, options);
  check_vector(file, "raw layout spacing", layout.spacing, true);
  check_vector(file, "raw layout origin", layout.origin, false);
  const std::size_t value_size = scalar_type_size(layout.type);
  const std::size_t size = size_of_file(file);
  const bool fits = count <= (std::numeric_limits<std::size_t>::max() - layout.header_bytes) / value_size;
  if (!fits || size != layout.header_bytes + count * value_size)
    fail(file, field,
         fmt::format("the file has {} bytes, but {} header bytes and {} x {} x {} values of type {} need {} "
                     "(wrong dims, type or header bytes?)",
                     size, layout.header_bytes, layout.dims[0], layout.dims[1], layout.dims[2],
                     scalar_type_name(layout.type),
                     fits ? fmt::format("{}", layout.header_bytes + count * value_size) : std::string("more")));
  Volume v =
      allocate_volume(file, "raw layout dims", {layout.dims[0], layout.dims[1], layout.dims[2]}, layout.type, options);
  v.spacing = layout.spacing;
  v.origin = layout.origin;
  FileSource src(file, layout.header_bytes);
  read_samples(src, layout.type, layout.big_endian, v, file, "data");
  return v;
}

ScalarType storage_type(const Volume& volume) {
  if (!scalar_type_is_integer(volume.source_type)) return volume.source_type;
  for (float v : volume.values)
    if (!scalar_type_holds(volume.source_type, v)) return ScalarType::f32;
  return volume.source_type;
}

void check_volume_for_writing(const fs::path& file, const Volume& volume) {
  for (int a = 0; a < 3; ++a)
    if (volume.dims[a] <= 0)
      throw Error(fmt::format("{}: cannot write: the volume's dims are {} x {} x {}", file.string(), volume.dims[0],
                              volume.dims[1], volume.dims[2]));
  if (volume.values.size() != volume.size())
    throw Error(fmt::format("{}: cannot write: {} values for {} x {} x {} points", file.string(), volume.values.size(),
                            volume.dims[0], volume.dims[1], volume.dims[2]));
  for (int a = 0; a < 3; ++a) {
    if (!(std::isfinite(volume.spacing[a]) && volume.spacing[a] > 0))
      throw Error(
          fmt::format("{}: cannot write: spacing {} is not a positive number", file.string(), volume.spacing[a]));
    if (!std::isfinite(volume.origin[a]))
      throw Error(fmt::format("{}: cannot write: the origin is not finite", file.string()));
  }
}

void write_samples_le(std::ostream& out, const Volume& volume, ScalarType type) {
  switch (type) {
    case ScalarType::u8:
      return write_typed<std::uint8_t>(out, volume.values);
    case ScalarType::i8:
      return write_typed<std::int8_t>(out, volume.values);
    case ScalarType::u16:
      return write_typed<std::uint16_t>(out, volume.values);
    case ScalarType::i16:
      return write_typed<std::int16_t>(out, volume.values);
    case ScalarType::u32:
      return write_typed<std::uint32_t>(out, volume.values);
    case ScalarType::i32:
      return write_typed<std::int32_t>(out, volume.values);
    case ScalarType::f32:
      return write_typed<float>(out, volume.values);
    case ScalarType::f64:
      return write_typed<double>(out, volume.values);
  }
}

}  // namespace volume_detail

Volume read_volume(const fs::path& file, const VolumeReadOptions& options) {
  const std::string name = lowercase(file.filename().string());
  if (ends_with(name, ".nrrd") || ends_with(name, ".nhdr")) return read_nrrd(file, options);
  if (ends_with(name, ".mhd") || ends_with(name, ".mha")) return read_metaimage(file, options);
  if (ends_with(name, ".vtk")) return read_vtk_structured_points(file, options);
  if (ends_with(name, ".vti")) return read_vti(file, options);
  if (ends_with(name, ".nii") || ends_with(name, ".nii.gz")) return read_nifti(file, options);
  if (options.raw) return read_raw(file, *options.raw, options);
  if (ends_with(name, ".raw"))
    throw Error(
        fmt::format("{}: a headerless .raw volume needs its layout: give at least its dims and type "
                    "(--dims NX NY NZ --type u8|i8|u16|i16|u32|i32|f32|f64)",
                    file.string()));
  throw Error(
      fmt::format("{}: unknown volume format '{}' (readable: .nrrd .nhdr .mhd .mha .vtk .vti .nii "
                  ".nii.gz, and headerless .raw with its layout)",
                  file.string(), file.extension().string()));
}

void write_volume(const fs::path& file, const Volume& volume) {
  const std::string name = lowercase(file.filename().string());
  check_volume_for_writing(file, volume);
  if (ends_with(name, ".nrrd")) return write_nrrd(file, volume);
  if (ends_with(name, ".vti")) return write_vti(file, volume);
  throw Error(fmt::format("{}: cannot write volume format '{}' (writable: .nrrd .vti)", file.string(),
                          file.extension().string()));
}

}  // namespace isohex
