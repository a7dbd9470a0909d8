#pragma once
/// \file decode.hpp
/// \brief What every volume reader shares: checking what a header declares before anything
/// is allocated, decoding stored samples into floats, and placing the grid in space.
///
/// Errors read "FILE: FIELD: WHAT", where FIELD is the header field that is wrong (for
/// example "field 'sizes'" or "DimSize"), so that a user can find the lie in the header.

#include "isohex/volume/byte_source.hpp"
#include "isohex/volume/volume.hpp"
#include "isohex/volume/volume_io.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string_view>

namespace isohex::io {
class TextScanner;
}

namespace isohex::volume_detail {

/// Throws isohex::Error "FILE: FIELD: WHAT".
[[noreturn]] void fail(const std::filesystem::path& file, std::string_view field, std::string_view what);

/// Checks declared dimensions (each positive and at most INT32_MAX, the product without
/// overflow, its float values within options.max_bytes); returns the number of points.
std::size_t check_dims(const std::filesystem::path& file, std::string_view field,
                       const std::array<std::int64_t, 3>& dims, const VolumeReadOptions& options);

/// check_dims, then a volume of that size with `type` as its source type (values zero).
/// Nothing is allocated when a check fails.
Volume allocate_volume(const std::filesystem::path& file, std::string_view field,
                       const std::array<std::int64_t, 3>& dims, ScalarType type, const VolumeReadOptions& options);

/// Throws unless every component of `v` is finite (and > 0 when `positive`).
void check_vector(const std::filesystem::path& file, std::string_view field, const Vec3& v, bool positive);

/// Sets spacing and origin from the world step of each grid axis (column i of `axes` is
/// the displacement from point i to point i+1 along axis i) and the world position of
/// point (0, 0, 0). A volume grid is axis-aligned with positive spacing, so axes that are
/// a signed permutation of the coordinate axes are realised by reordering the values; a
/// rotated grid keeps its own axes (spacing = the step lengths) and loses its rotation.
void place_grid(Volume& volume, const Eigen::Matrix3d& axes, const Vec3& origin, const std::filesystem::path& file,
                std::string_view field);

/// Decodes volume.size() samples of `type` (byte order `big_endian`) from `source` into
/// volume.values. `what` names the data in messages ("data file 'x.raw'", ...).
void read_samples(ByteSource& source, ScalarType type, bool big_endian, Volume& volume,
                  const std::filesystem::path& file, std::string_view what);

/// Decodes volume.size() whitespace-separated numbers from `scanner` into volume.values;
/// each must be a finite number (and an integer in range for an integer source type).
void read_ascii_samples(io::TextScanner& scanner, Volume& volume, std::string_view what);

/// Parses exactly `n` numbers separated by spaces (and, when `commas`, commas); false if
/// `text` is not that.
bool parse_numbers(std::string_view text, double* out, std::size_t n, bool commas = false);

/// Lowercase ASCII copy.
std::string lowercase(std::string_view s);

/// `s` without leading and trailing blanks (spaces, tabs, CR, LF).
std::string_view trim(std::string_view s);

}  // namespace isohex::volume_detail
