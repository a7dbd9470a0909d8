#pragma once
/// \file formats.hpp
/// \brief The per-format readers and writers behind read_volume and write_volume.
///
/// Why isohex parses NRRD and NIfTI itself instead of calling teem (libteem-dev) or
/// niftilib (libnifti2-dev): both read the data into a buffer of their own type that would
/// then be converted to floats (twice the memory of decoding chunk by chunk into the
/// volume), neither applies a caller's memory limit before it allocates, and both report
/// faults as free text in their own channels (teem's global, not thread-safe biff buffer;
/// niftilib's stderr) rather than as an error naming the file and the header field. Both
/// formats are a short header in front of raw or gzip data, which the MetaImage and VTK
/// readers here decode anyway; the formats' specifications were followed.

#include "isohex/error.hpp"
#include "isohex/volume/byte_source.hpp"
#include "isohex/volume/volume_io.hpp"

#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>

namespace isohex::volume_detail {

Volume read_raw(const std::filesystem::path& file, const RawLayout& layout, const VolumeReadOptions& options);
Volume read_nrrd(const std::filesystem::path& file, const VolumeReadOptions& options);
Volume read_metaimage(const std::filesystem::path& file, const VolumeReadOptions& options);
Volume read_vtk_structured_points(const std::filesystem::path& file, const VolumeReadOptions& options);
Volume read_vti(const std::filesystem::path& file, const VolumeReadOptions& options);
Volume read_nifti(const std::filesystem::path& file, const VolumeReadOptions& options);

void write_nrrd(const std::filesystem::path& file, const Volume& volume);
void write_vti(const std::filesystem::path& file, const Volume& volume);

/// The type a writer stores values as: the source type when it holds every value exactly
/// (so integer scans stay compact and round trips are bit-exact), f32 otherwise.
ScalarType storage_type(const Volume& volume);

/// Throws isohex::Error naming `file` unless `volume` can be written: positive dims whose
/// product matches the values, finite positive spacing and a finite origin.
void check_volume_for_writing(const std::filesystem::path& file, const Volume& volume);

/// Writes `volume`'s values as `type`, little-endian, to `out` in chunks.
void write_samples_le(std::ostream& out, const Volume& volume, ScalarType type);

/// Runs `parse(text, whole)` on the first megabyte of `file`, and again on the whole file
/// if that fails while the file goes on: headers longer than that are rare, and reading a
/// large file whole next to its decoded values is what the readers avoid. `parse` must not
/// keep references into `text`.
template <class Parse>
auto parse_header(const std::filesystem::path& file, Parse&& parse) {
  constexpr std::size_t kPrefix = std::size_t{1} << 20;
  std::string text = read_prefix(file, kPrefix);
  if (text.size() < kPrefix) return parse(std::string_view(text), true);
  try {
    return parse(std::string_view(text), false);
  } catch (const Error&) {
  }
  text = read_prefix(file, size_of_file(file));
  return parse(std::string_view(text), true);
}

}  // namespace isohex::volume_detail
