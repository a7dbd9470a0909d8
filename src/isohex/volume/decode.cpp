#include "isohex/volume/decode.hpp"

#include "isohex/io/big_endian.hpp"

#include "isohex/error.hpp"
#include "isohex/io/format_support.hpp"
#include "isohex/io/text_scanner.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace isohex::volume_detail {

namespace fs = std::filesystem;

namespace {

/// Bytes decoded per step: large enough to amortise the reads, small next to any volume.
constexpr std::size_t kChunkBytes = std::size_t{1} << 20;

template <class T>
void decode_typed(ByteSource& source, bool big_endian, Volume& volume, const fs::path& file, std::string_view what) {
  const bool swap = sizeof(T) > 1 && big_endian != (std::endian::native == std::endian::big);
  const std::size_t n = volume.size();
  const std::size_t per_chunk = kChunkBytes / sizeof(T);
  std::vector<unsigned char> buf(std::min(n, per_chunk) * sizeof(T));
  float* out = volume.values.data();
  for (std::size_t first = 0; first < n; first += per_chunk) {
    const std::size_t count = std::min(per_chunk, n - first);
    const std::size_t got = read_full(source, buf.data(), count * sizeof(T));
    if (got < count * sizeof(T))
      fail(file, what,
           fmt::format("ends after {} of the {} bytes that {} values of type {} need (truncated, or the header's "
                       "sizes or type are wrong)",
                       first * sizeof(T) + got, n * sizeof(T), n, scalar_type_name(volume.source_type)));
    for (std::size_t i = 0; i < count; ++i)
      out[first + i] = static_cast<float>(io::load_swapped<T>(buf.data() + i * sizeof(T), swap));
  }
}

}  // namespace

void fail(const fs::path& file, std::string_view field, std::string_view what) {
  throw Error(fmt::format("{}: {}: {}", file.string(), field, what));
}

std::size_t check_dims(const fs::path& file, std::string_view field, const std::array<std::int64_t, 3>& dims,
                       const VolumeReadOptions& options) {
  constexpr char kAxis[] = "xyz";
  std::size_t count = 1;
  bool overflow = false;
  for (int a = 0; a < 3; ++a) {
    if (dims[a] <= 0)
      fail(file, field, fmt::format("the {} size is {}; every size must be positive", kAxis[a], dims[a]));
    if (dims[a] > std::numeric_limits<Index>::max())
      fail(file, field,
           fmt::format("the {} size {} exceeds isohex's limit of {} points per axis", kAxis[a], dims[a],
                       std::numeric_limits<Index>::max()));
    const auto d = static_cast<std::size_t>(dims[a]);
    if (count > std::numeric_limits<std::size_t>::max() / d)
      overflow = true;
    else
      count *= d;
  }
  const std::string shape = fmt::format("{} x {} x {}", dims[0], dims[1], dims[2]);
  if (overflow || count > std::numeric_limits<std::size_t>::max() / sizeof(double))
    fail(file, field, fmt::format("{} points overflow a 64-bit size: a corrupt header", shape));
  const std::size_t bytes = count * sizeof(float);
  if (bytes > options.max_bytes)
    fail(file, field,
         fmt::format("{} = {} points need {} bytes as float values, more than the limit of {} bytes "
                     "(VolumeReadOptions::max_bytes, --max-memory)",
                     shape, count, bytes, options.max_bytes));
  return count;
}

Volume allocate_volume(const fs::path& file, std::string_view field, const std::array<std::int64_t, 3>& dims,
                       ScalarType type, const VolumeReadOptions& options) {
  const std::size_t count = check_dims(file, field, dims, options);
  Volume v;
  for (int a = 0; a < 3; ++a) v.dims[a] = static_cast<Index>(dims[a]);
  v.source_type = type;
  v.values.resize(count);
  return v;
}

void check_vector(const fs::path& file, std::string_view field, const Vec3& v, bool positive) {
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(v[a])) fail(file, field, fmt::format("component {} is not a finite number", a + 1));
    if (positive && !(v[a] > 0)) fail(file, field, fmt::format("component {} is {}; it must be positive", a + 1, v[a]));
  }
}

void place_grid(Volume& volume, const Eigen::Matrix3d& axes, const Vec3& origin, const fs::path& file,
                std::string_view field) {
  check_vector(file, field, origin, false);
  std::array<int, 3> target{};  // world axis each grid axis runs along, if a signed permutation
  bool permutation = true;
  for (int j = 0; j < 3; ++j) {
    const Vec3 c = axes.col(j);
    check_vector(file, field, c, false);
    if (c.norm() == 0) fail(file, field, fmt::format("axis {} has a zero step vector", j + 1));
    int nonzero = 0;
    for (int r = 0; r < 3; ++r)
      if (c[r] != 0) {
        ++nonzero;
        target[j] = r;
      }
    permutation = permutation && nonzero == 1;
  }
  permutation = permutation && target[0] != target[1] && target[0] != target[2] && target[1] != target[2];
  volume.origin = origin;
  if (!permutation) {  // rotated: keep the grid's own axes, scaled by the step lengths
    for (int j = 0; j < 3; ++j) volume.spacing[j] = axes.col(j).norm();
    return;
  }
  bool identity = true;
  for (int j = 0; j < 3; ++j) identity = identity && target[j] == j && axes(j, j) > 0;
  if (identity) {
    volume.spacing = axes.diagonal();
    return;
  }
  // Reorder the values so that grid axis j runs along world axis target[j], forwards.
  const std::array<Index, 3> old_dims = volume.dims;
  std::array<Index, 3> dims{};
  for (int j = 0; j < 3; ++j) {
    const int r = target[j];
    const double step = axes(r, j);
    dims[r] = old_dims[j];
    volume.spacing[r] = std::abs(step);
    volume.origin[r] = origin[r] + (step < 0 ? (old_dims[j] - 1) * step : 0.0);
  }
  const std::array<std::size_t, 3> stride = {1, static_cast<std::size_t>(dims[0]),
                                             static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1])};
  std::vector<float> values(volume.values.size());
  std::size_t src = 0;
  for (Index k = 0; k < old_dims[2]; ++k)
    for (Index jj = 0; jj < old_dims[1]; ++jj)
      for (Index i = 0; i < old_dims[0]; ++i, ++src) {
        const std::array<Index, 3> idx = {i, jj, k};
        std::size_t dst = 0;
        for (int j = 0; j < 3; ++j) {
          const int r = target[j];
          const Index pos = axes(r, j) > 0 ? idx[j] : old_dims[j] - 1 - idx[j];
          dst += static_cast<std::size_t>(pos) * stride[r];
        }
        values[dst] = volume.values[src];
      }
  volume.values = std::move(values);
  volume.dims = dims;
}

void read_samples(ByteSource& source, ScalarType type, bool big_endian, Volume& volume, const fs::path& file,
                  std::string_view what) {
  switch (type) {
    case ScalarType::u8:
      return decode_typed<std::uint8_t>(source, big_endian, volume, file, what);
    case ScalarType::i8:
      return decode_typed<std::int8_t>(source, big_endian, volume, file, what);
    case ScalarType::u16:
      return decode_typed<std::uint16_t>(source, big_endian, volume, file, what);
    case ScalarType::i16:
      return decode_typed<std::int16_t>(source, big_endian, volume, file, what);
    case ScalarType::u32:
      return decode_typed<std::uint32_t>(source, big_endian, volume, file, what);
    case ScalarType::i32:
      return decode_typed<std::int32_t>(source, big_endian, volume, file, what);
    case ScalarType::f32:
      return decode_typed<float>(source, big_endian, volume, file, what);
    case ScalarType::f64:
      return decode_typed<double>(source, big_endian, volume, file, what);
  }
}

void read_ascii_samples(io::TextScanner& scanner, Volume& volume, std::string_view what) {
  const std::size_t n = volume.size();
  const bool integer = scalar_type_is_integer(volume.source_type);
  for (std::size_t i = 0; i < n; ++i) {
    const std::string_view tok = scanner.next();
    if (tok.empty()) scanner.fail(fmt::format("{} ends after {} of its {} values", what, i, n));
    double v = 0;
    if (!io::parse_double(tok, v))
      scanner.fail(fmt::format("{}: value {} '{}' is not a finite number", what, i, io::printable(tok)));
    const auto f = static_cast<float>(v);
    if (integer && !scalar_type_holds(volume.source_type, f))
      scanner.fail(fmt::format("{}: value {} '{}' is not a {} value", what, i, io::printable(tok),
                               scalar_type_name(volume.source_type)));
    volume.values[i] = f;
  }
}

bool parse_numbers(std::string_view text, double* out, std::size_t n, bool commas) {
  std::size_t found = 0, pos = 0;
  auto is_sep = [commas](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || (commas && c == ','); };
  while (true) {
    while (pos < text.size() && is_sep(text[pos])) ++pos;
    if (pos == text.size()) break;
    std::size_t end = pos;
    while (end < text.size() && !is_sep(text[end])) ++end;
    if (found == n || !io::parse_double(text.substr(pos, end - pos), out[found])) return false;
    ++found;
    pos = end;
  }
  return found == n;
}

std::string lowercase(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return out;
}

std::string_view trim(std::string_view s) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

}  // namespace isohex::volume_detail
