#pragma once
/// \file volume_io.hpp
/// \brief Reading and writing volumes; the format is chosen by extension (or given for raw).

#include "isohex/volume/volume.hpp"

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

namespace isohex {

/// How to interpret a headerless raw file.
struct RawLayout {
  std::array<Index, 3> dims{0, 0, 0};
  ScalarType type = ScalarType::u8;
  bool big_endian = false;
  Vec3 spacing{1, 1, 1};
  Vec3 origin{0, 0, 0};
  std::size_t header_bytes = 0;  ///< bytes to skip before the data
};

struct VolumeReadOptions {
  /// Refuse volumes whose float values would need more than this many bytes.
  std::size_t max_bytes = std::size_t{8} << 30;
  /// Layout for raw files (required for .raw, ignored otherwise).
  std::optional<RawLayout> raw;
};

/// Reads a volume: .raw (with options.raw), .nrrd/.nhdr, .mhd/.mha, .vtk (STRUCTURED_POINTS),
/// .vti, .nii/.nii.gz. Throws isohex::Error naming the file, the field and the fault.
Volume read_volume(const std::filesystem::path& file, const VolumeReadOptions& options = {});

/// Writes a volume as .nrrd or .vti (chosen by extension), atomically.
void write_volume(const std::filesystem::path& file, const Volume& volume);

}  // namespace isohex
