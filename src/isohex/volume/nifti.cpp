// NIfTI-1 single files (.nii, and .nii.gz read through zlib): the 348-byte header in
// either byte order (detected from sizeof_hdr), the voxels at vox_offset, scl_slope and
// scl_inter applied when the slope is nonzero, and the grid placed by the sform (when
// sform_code > 0), else the qform (qform_code > 0), else pixdim alone.
#include "isohex/error.hpp"
#include "isohex/io/big_endian.hpp"
#include "isohex/volume/decode.hpp"
#include "isohex/volume/formats.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

namespace isohex::volume_detail {

namespace {

namespace fs = std::filesystem;

constexpr std::size_t kHeaderSize = 348;

/// Typed access to the header bytes in the file's byte order.
class Header {
 public:
  explicit Header(const unsigned char* bytes) { std::memcpy(b_, bytes, kHeaderSize); }
  void set_swap(bool swap) { swap_ = swap; }
  template <class T>
  [[nodiscard]] T get(std::size_t offset) const {
    return io::load_swapped<T>(b_ + offset, swap_);
  }
  [[nodiscard]] std::int16_t i16(std::size_t o) const { return get<std::int16_t>(o); }
  [[nodiscard]] float f32(std::size_t o) const { return get<float>(o); }
  [[nodiscard]] const unsigned char* bytes() const { return b_; }

 private:
  unsigned char b_[kHeaderSize];
  bool swap_ = false;
};

// Field offsets of the NIfTI-1 header.
constexpr std::size_t kDim = 40, kDatatype = 70, kBitpix = 72, kPixdim = 76, kVoxOffset = 108, kSclSlope = 112,
                      kSclInter = 116, kQformCode = 252, kSformCode = 254, kQuatern = 256, kQoffset = 268, kSrow = 280,
                      kMagic = 344;

std::string_view datatype_name(int code) {
  switch (code) {
    case 1:
      return "binary";
    case 32:
      return "complex64";
    case 128:
      return "rgb24";
    case 1024:
      return "int64";
    case 1280:
      return "uint64";
    case 1536:
      return "float128";
    case 1792:
      return "complex128";
    case 2048:
      return "complex256";
    case 2304:
      return "rgba32";
    default:
      return "unknown";
  }
}

std::optional<ScalarType> datatype(int code) {
  switch (code) {
    case 2:
      return ScalarType::u8;
    case 4:
      return ScalarType::i16;
    case 8:
      return ScalarType::i32;
    case 16:
      return ScalarType::f32;
    case 64:
      return ScalarType::f64;
    case 256:
      return ScalarType::i8;
    case 512:
      return ScalarType::u16;
    case 768:
      return ScalarType::u32;
    default:
      return std::nullopt;
  }
}

/// Grid axes and origin from the header's transforms (NIfTI-1 "methods" 3, 2 and 1).
void transform(const Header& h, const Vec3& pixdim, Eigen::Matrix3d& axes, Vec3& origin) {
  if (h.i16(kSformCode) > 0) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) axes(r, c) = h.f32(kSrow + 16 * r + 4 * c);
      origin[r] = h.f32(kSrow + 16 * r + 12);
    }
    return;
  }
  if (h.i16(kQformCode) > 0) {
    const double b = h.f32(kQuatern), c = h.f32(kQuatern + 4), d = h.f32(kQuatern + 8);
    const double a = std::sqrt(std::max(0.0, 1.0 - (b * b + c * c + d * d)));
    Eigen::Matrix3d rot;
    rot << a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c),  //
        2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b),     //
        2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b;
    const double qfac = h.f32(kPixdim) < 0 ? -1.0 : 1.0;
    axes = rot * Vec3(pixdim[0], pixdim[1], qfac * pixdim[2]).asDiagonal();
    for (int r = 0; r < 3; ++r) origin[r] = h.f32(kQoffset + 4 * r);
    return;
  }
  axes = pixdim.asDiagonal();
  origin.setZero();
}

}  // namespace

Volume read_nifti(const fs::path& file, const VolumeReadOptions& options) {
  const std::string name = lowercase(file.filename().string());
  const bool gz = name.size() > 3 && name.substr(name.size() - 3) == ".gz";
  FileSource raw(file, 0);
  std::unique_ptr<InflateSource> inflated;
  if (gz) inflated = std::make_unique<InflateSource>(raw, file, "gzip data");
  ByteSource& src = gz ? static_cast<ByteSource&>(*inflated) : raw;

  unsigned char bytes[kHeaderSize];
  const std::size_t got = read_full(src, bytes, kHeaderSize);
  if (got < kHeaderSize)
    fail(file, "header", fmt::format("the file holds {} bytes, fewer than the 348 of a NIfTI-1 header", got));
  Header h(bytes);
  // sizeof_hdr is 348 in the file's byte order, which tells that order.
  const auto native_size = h.get<std::int32_t>(0);
  if (native_size != 348) {
    h.set_swap(true);
    const auto swapped_size = h.get<std::int32_t>(0);
    if (swapped_size != 348) {
      if (native_size == 540 || swapped_size == 540)
        fail(file, "sizeof_hdr", "540: a NIfTI-2 file; isohex reads NIfTI-1");
      fail(file, "sizeof_hdr",
           fmt::format("is {} (or {} byte-swapped), not 348: not a NIfTI-1 file", native_size, swapped_size));
    }
  }
  const unsigned char* magic = h.bytes() + kMagic;
  if (std::memcmp(magic, "ni1\0", 4) == 0)
    fail(file, "magic", "'ni1': the header of a .hdr/.img pair; isohex reads single-file NIfTI (.nii, magic 'n+1')");
  if (std::memcmp(magic, "n+1\0", 4) != 0) fail(file, "magic", "is not 'n+1': not a single-file NIfTI-1 header");

  const int ndim = h.i16(kDim);
  if (ndim < 1 || ndim > 7) fail(file, "dim[0]", fmt::format("is {}; it must be 1 to 7", ndim));
  std::array<std::int64_t, 3> dims = {1, 1, 1};
  for (int a = 0; a < std::min(ndim, 3); ++a) dims[a] = h.i16(kDim + 2 * (a + 1));
  for (int a = 4; a <= ndim; ++a)
    if (h.i16(kDim + 2 * a) > 1)
      fail(file, fmt::format("dim[{}]", a),
           fmt::format("is {}: a {}-D series; isohex reads one 3-D volume", h.i16(kDim + 2 * a), ndim));
  const int code = h.i16(kDatatype);
  const auto type = datatype(code);
  if (!type)
    fail(file, "datatype",
         fmt::format("{} ({}) is not supported (isohex reads 8- to 32-bit integers, float32 "
                     "and float64)",
                     code, datatype_name(code)));
  const int bitpix = h.i16(kBitpix);
  if (static_cast<std::size_t>(bitpix) != 8 * scalar_type_size(*type))
    fail(file, "bitpix", fmt::format("is {}, but datatype {} has {} bits", bitpix, code, 8 * scalar_type_size(*type)));
  const double vox_offset = h.f32(kVoxOffset);
  if (!(vox_offset >= static_cast<double>(kHeaderSize) && vox_offset <= 1e15) || vox_offset != std::floor(vox_offset))
    fail(file, "vox_offset", fmt::format("is {}; it must be a whole number of bytes >= 348", vox_offset));
  Vec3 pixdim;
  for (int a = 0; a < 3; ++a) {
    pixdim[a] = a < ndim ? std::abs(h.f32(kPixdim + 4 * (a + 1))) : 1.0;
    if (h.i16(kSformCode) <= 0 && !(std::isfinite(pixdim[a]) && pixdim[a] > 0))  // the sform has its own
      fail(file, fmt::format("pixdim[{}]", a + 1), fmt::format("is {}; a voxel size must be positive", pixdim[a]));
  }

  const std::size_t count = check_dims(file, "dim", dims, options);
  const auto offset = static_cast<std::size_t>(vox_offset);
  if (!gz) {
    const std::size_t size = size_of_file(file);
    const std::size_t bytes = count * scalar_type_size(*type);
    if (size < offset || size - offset < bytes)
      fail(file, "dim",
           fmt::format("{} x {} x {} voxels of {} need {} bytes after vox_offset {}, but the file holds {} (truncated, "
                       "or the header lies)",
                       dims[0], dims[1], dims[2], scalar_type_name(*type), bytes, offset,
                       size > offset ? size - offset : 0));
  }
  Volume v = allocate_volume(file, "dim", dims, *type, options);
  if (!src.skip(offset - kHeaderSize))
    fail(file, "vox_offset", fmt::format("{} lies beyond the end of the data", offset));
  const bool big_endian = (std::endian::native == std::endian::big) != (native_size != 348);
  read_samples(src, *type, big_endian, v, file, "voxel data");

  const double slope = h.f32(kSclSlope), inter = h.f32(kSclInter);
  if (std::isfinite(slope) && slope != 0 && std::isfinite(inter) && !(slope == 1 && inter == 0)) {
    for (float& x : v.values) x = static_cast<float>(x * slope + inter);
    v.source_type = ScalarType::f32;  // scaled values no longer fit the stored type
  }
  Eigen::Matrix3d axes;
  Vec3 origin;
  transform(h, pixdim, axes, origin);
  const char* field = h.i16(kSformCode) > 0   ? "srow_x/y/z (sform)"
                      : h.i16(kQformCode) > 0 ? "quatern/qoffset (qform)"
                                              : "pixdim";
  place_grid(v, axes, origin, file, field);
  return v;
}

}  // namespace isohex::volume_detail
