// Every reader on small files written here byte by byte (independently of the library's
// writers): all types and byte orders, compressed and ASCII data, the header variants of
// each format, and grids whose axes are flipped, permuted or rotated.
#include "isohex/error.hpp"
#include "isohex/volume/volume_io.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <fstream>

using namespace isohex;
using isohex::test::scratch_dir;
namespace fs = std::filesystem;

namespace {

constexpr Index NX = 5, NY = 4, NZ = 3;
constexpr ScalarType kAllTypes[] = {ScalarType::u8,  ScalarType::i8,  ScalarType::u16, ScalarType::i16,
                                    ScalarType::u32, ScalarType::i32, ScalarType::f32, ScalarType::f64};

/// The test field, chosen to fit every type: 0..59 unsigned, -30..29 signed, quarters for floats.
double field(Index i, Index j, Index k, ScalarType t) {
  const double n = i + NX * (j + NY * k);
  switch (t) {
    case ScalarType::u8:
    case ScalarType::u16:
    case ScalarType::u32:
      return n;
    case ScalarType::f32:
    case ScalarType::f64:
      return n * 0.25 - 7.5;
    default:
      return n - 30;
  }
}

template <class T>
void put(std::string& out, double v, bool big) {
  const T x = static_cast<T>(v);
  unsigned char b[sizeof(T)];
  std::memcpy(b, &x, sizeof(T));
  if (big != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
  out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

void put_value(std::string& out, double v, ScalarType t, bool big) {
  switch (t) {
    case ScalarType::u8:
      return put<std::uint8_t>(out, v, big);
    case ScalarType::i8:
      return put<std::int8_t>(out, v, big);
    case ScalarType::u16:
      return put<std::uint16_t>(out, v, big);
    case ScalarType::i16:
      return put<std::int16_t>(out, v, big);
    case ScalarType::u32:
      return put<std::uint32_t>(out, v, big);
    case ScalarType::i32:
      return put<std::int32_t>(out, v, big);
    case ScalarType::f32:
      return put<float>(out, v, big);
    case ScalarType::f64:
      return put<double>(out, v, big);
  }
}

/// The test field stored as `t` in byte order `big`, x fastest.
std::string encode(ScalarType t, bool big) {
  std::string out;
  for (Index k = 0; k < NZ; ++k)
    for (Index j = 0; j < NY; ++j)
      for (Index i = 0; i < NX; ++i) put_value(out, field(i, j, k, t), t, big);
  return out;
}

std::string ascii(ScalarType t) {
  std::string out;
  for (Index k = 0; k < NZ; ++k)
    for (Index j = 0; j < NY; ++j)
      for (Index i = 0; i < NX; ++i) out += std::to_string(field(i, j, k, t)) + (i + 1 == NX ? "\n" : " ");
  return out;
}

void write(const fs::path& file, const std::string& bytes) { std::ofstream(file, std::ios::binary) << bytes; }

std::string gzip(const fs::path& dir, const std::string& bytes) {
  write(dir / "plain.bin", bytes);
  EXPECT_EQ(
      std::system(("gzip -c '" + (dir / "plain.bin").string() + "' > '" + (dir / "plain.gz").string() + "'").c_str()),
      0);
  std::ifstream in(dir / "plain.gz", std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

/// Checks dims, type and that value (i, j, k) is the field at `map(i, j, k)` of the file.
template <class Map>
void expect_field(const Volume& v, ScalarType t, std::array<Index, 3> dims, Map map, const std::string& what) {
  ASSERT_EQ(v.dims, dims) << what;
  EXPECT_EQ(v.source_type, t) << what;
  for (Index k = 0; k < dims[2]; ++k)
    for (Index j = 0; j < dims[1]; ++j)
      for (Index i = 0; i < dims[0]; ++i) {
        const auto [a, b, c] = map(i, j, k);
        ASSERT_EQ(v.at(i, j, k), static_cast<float>(field(a, b, c, t))) << what << " at " << i << " " << j << " " << k;
      }
}

void expect_field(const Volume& v, ScalarType t, const std::string& what) {
  expect_field(
      v, t, {NX, NY, NZ},
      [](Index i, Index j, Index k) {
        return std::array<Index, 3>{i, j, k};
      },
      what);
}

const char* nrrd_type(ScalarType t) {
  constexpr const char* names[] = {"uchar", "signed char", "ushort", "short", "uint", "int", "float", "double"};
  return names[static_cast<int>(t)];
}

std::string nrrd_head(ScalarType t, const std::string& extra) {
  return std::string("NRRD0004\ntype: ") + nrrd_type(t) + "\ndimension: 3\nsizes: 5 4 3\n" + extra;
}

}  // namespace

TEST(VolumeNrrd, AttachedRawEveryTypeAndByteOrder) {
  const fs::path dir = scratch_dir();
  for (ScalarType t : kAllTypes)
    for (bool big : {false, true}) {
      const fs::path f = dir / "v.nrrd";
      write(f,
            nrrd_head(t, std::string("endian: ") + (big ? "big" : "little") + "\nencoding: raw\n\n") + encode(t, big));
      expect_field(read_volume(f), t, std::string(scalar_type_name(t)) + (big ? " big" : " little"));
    }
}

TEST(VolumeNrrd, GzipAsciiAndSkips) {
  const fs::path dir = scratch_dir();
  const ScalarType t = ScalarType::i16;
  write(dir / "gz.nrrd",
        nrrd_head(t, "endian: big\nencoding: gzip\nspacings: 0.5 1 2\n\n") + gzip(dir, encode(t, true)));
  const Volume gz = read_volume(dir / "gz.nrrd");
  expect_field(gz, t, "gzip");
  EXPECT_EQ(gz.spacing, Vec3(0.5, 1, 2));

  write(dir / "text.nrrd", nrrd_head(ScalarType::f32, "encoding: ascii\r\n\r\n") + ascii(ScalarType::f32));
  expect_field(read_volume(dir / "text.nrrd"), ScalarType::f32, "ascii");

  // byte skip, line skip, and byte skip -1 (the data is the end of the file).
  write(dir / "skip.raw", "junk line\nmore\n0123456" + encode(t, false));
  write(dir / "bytes.nhdr",
        nrrd_head(t, "endian: little\nencoding: raw\nline skip: 2\nbyte skip: 7\ndata file: skip.raw\n"));
  expect_field(read_volume(dir / "bytes.nhdr"), t, "line and byte skip");
  write(dir / "end.nhdr", nrrd_head(t, "endian: little\nencoding: raw\nbyte skip: -1\ndatafile: skip.raw\n"));
  expect_field(read_volume(dir / "end.nhdr"), t, "byte skip -1");

  // A LIST of data files, one slice each.
  const std::string all = encode(t, false);
  const std::size_t slice = all.size() / NZ;
  std::string head = nrrd_head(t, "endian: little\nencoding: raw\ndata file: LIST\n");
  for (Index k = 0; k < NZ; ++k) {
    write(dir / ("s" + std::to_string(k) + ".raw"), all.substr(k * slice, slice));
    head += "s" + std::to_string(k) + ".raw\n";
  }
  write(dir / "list.nhdr", head);
  expect_field(read_volume(dir / "list.nhdr"), t, "LIST");
}

TEST(VolumeNrrd, SpaceDirectionsFlipPermuteOrRotate) {
  const fs::path dir = scratch_dir();
  const ScalarType t = ScalarType::u8;
  const std::string data = encode(t, false);
  // x runs backwards from 10: the grid is flipped so that spacing is positive.
  write(dir / "flip.nrrd", nrrd_head(t,
                                     "encoding: raw\nspace dimension: 3\nspace directions: (-2,0,0) (0,3,0) "
                                     "(0,0,1.5)\nspace origin: (10,20,30)\n\n") +
                               data);
  const Volume flip = read_volume(dir / "flip.nrrd");
  expect_field(
      flip, t, {NX, NY, NZ},
      [](Index i, Index j, Index k) {
        return std::array<Index, 3>{NX - 1 - i, j, k};
      },
      "flip");
  EXPECT_EQ(flip.spacing, Vec3(2, 3, 1.5));
  EXPECT_EQ(flip.origin, Vec3(2, 20, 30));
  // Grid axis 0 runs along world y, axis 1 along world x: the values are transposed.
  write(dir / "perm.nrrd",
        nrrd_head(t, "encoding: raw\nspace: RAS\nspace directions: (0,2,0) (1,0,0) (0,0,1)\n\n") + data);
  const Volume perm = read_volume(dir / "perm.nrrd");
  expect_field(
      perm, t, {NY, NX, NZ},
      [](Index i, Index j, Index k) {
        return std::array<Index, 3>{j, i, k};
      },
      "perm");
  EXPECT_EQ(perm.spacing, Vec3(1, 2, 1));
  // A rotated grid keeps its own axes and the lengths of its steps.
  write(dir / "rot.nrrd", nrrd_head(t,
                                    "encoding: raw\nspace directions: (0.6,0.8,0) (-0.8,0.6,0) (0,0,2)\n"
                                    "space origin: (1,2,3)\n\n") +
                              data);
  const Volume rot = read_volume(dir / "rot.nrrd");
  expect_field(rot, t, "rotated");
  EXPECT_NEAR((rot.spacing - Vec3(1, 1, 2)).norm(), 0, 1e-15);
  EXPECT_EQ(rot.origin, Vec3(1, 2, 3));
}

TEST(VolumeMetaImage, LocalSeparateCompressedAscii) {
  const fs::path dir = scratch_dir();
  write(dir / "msb.mha",
        "ObjectType = Image\nNDims = 3\nDimSize = 5 4 3\nElementType = MET_USHORT\n"
        "ElementByteOrderMSB = True\nElementSpacing = 0.5 0.25 2\nOffset = -1 2.5 3\n"
        "ElementDataFile = LOCAL\n" +
            encode(ScalarType::u16, true));
  const Volume msb = read_volume(dir / "msb.mha");
  expect_field(msb, ScalarType::u16, "MSB LOCAL");
  EXPECT_EQ(msb.spacing, Vec3(0.5, 0.25, 2));
  EXPECT_EQ(msb.origin, Vec3(-1, 2.5, 3));

  write(dir / "data.bin", "HEADER!" + encode(ScalarType::f64, false));
  write(dir / "sep.mhd",
        "NDims = 3\nDimSize = 5 4 3\nElementType = MET_DOUBLE\nElementSize = 3 3 3\n"
        "HeaderSize = 7\nBinaryDataByteOrderMSB = False\nElementDataFile = data.bin\n");
  const Volume sep = read_volume(dir / "sep.mhd");
  expect_field(sep, ScalarType::f64, "separate file");
  EXPECT_EQ(sep.spacing, Vec3(3, 3, 3));

  write(dir / "z.mha",
        "NDims = 3\nDimSize = 5 4 3\nElementType = MET_INT\nCompressedData = True\n"
        "ElementDataFile = LOCAL\n" +
            gzip(dir, encode(ScalarType::i32, false)));
  expect_field(read_volume(dir / "z.mha"), ScalarType::i32, "compressed");

  write(dir / "t.mha",
        "NDims = 3\nDimSize = 5 4 3\nElementType = MET_CHAR\nBinaryData = False\n"
        "TransformMatrix = 1 0 0 0 -1 0 0 0 1\nElementDataFile = LOCAL\n" +
            ascii(ScalarType::i8));
  const Volume t = read_volume(dir / "t.mha");
  expect_field(
      t, ScalarType::i8, {NX, NY, NZ},
      [](Index i, Index j, Index k) {
        return std::array<Index, 3>{i, NY - 1 - j, k};
      },
      "ascii, y flipped by TransformMatrix");
  EXPECT_EQ(t.origin, Vec3(0, -3, 0));
}

TEST(VolumeLegacyVtk, AsciiAndBinary) {
  const fs::path dir = scratch_dir();
  write(dir / "a.vtk",
        "# vtk DataFile Version 3.0\nsome title\nASCII\nDATASET STRUCTURED_POINTS\n"
        "DIMENSIONS 5 4 3\nSPACING 0.5 1 2\nORIGIN 1 2 3\nPOINT_DATA 60\nSCALARS s short 1\n"
        "LOOKUP_TABLE default\n" +
            ascii(ScalarType::i16));
  const Volume a = read_volume(dir / "a.vtk");
  expect_field(a, ScalarType::i16, "ascii");
  EXPECT_EQ(a.spacing, Vec3(0.5, 1, 2));
  EXPECT_EQ(a.origin, Vec3(1, 2, 3));

  write(dir / "b.vtk",
        "# vtk DataFile Version 2.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\nORIGIN 0 0 0\n"
        "ASPECT_RATIO 2 2 2\nDIMENSIONS 5 4 3\nPOINT_DATA 60\nSCALARS s double\n" +
            encode(ScalarType::f64, true) + "\n");
  const Volume b = read_volume(dir / "b.vtk");
  expect_field(b, ScalarType::f64, "binary without LOOKUP_TABLE");
  EXPECT_EQ(b.spacing, Vec3(2, 2, 2));

  // Binary data that begins with whitespace bytes (newline, space) must not be skipped.
  std::string bytes = encode(ScalarType::u8, true);
  bytes[0] = '\n';
  bytes[1] = ' ';
  write(dir / "c.vtk",
        "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 5 4 3\n"
        "POINT_DATA 60\nSCALARS s unsigned_char\n" +
            bytes);
  const Volume c = read_volume(dir / "c.vtk");
  EXPECT_EQ(c.at(0, 0, 0), '\n');
  EXPECT_EQ(c.at(1, 0, 0), ' ');
  EXPECT_EQ(c.at(4, 3, 2), 59);
}

namespace {

/// A NIfTI-1 header for the test field, in either byte order.
std::string nifti_header(ScalarType t, bool big, float slope, float inter, int sform, int qform) {
  std::string h(352, '\0');
  auto i32 = [&](std::size_t at, std::int32_t v) {
    std::string s;
    put<std::int32_t>(s, v, big);
    h.replace(at, 4, s);
  };
  auto i16 = [&](std::size_t at, std::int16_t v) {
    std::string s;
    put<std::int16_t>(s, v, big);
    h.replace(at, 2, s);
  };
  auto f32 = [&](std::size_t at, float v) {
    std::string s;
    put<float>(s, v, big);
    h.replace(at, 4, s);
  };
  i32(0, 348);
  const std::int16_t dim[8] = {3, NX, NY, NZ, 1, 1, 1, 1};
  for (int a = 0; a < 8; ++a) i16(40 + 2 * a, dim[a]);
  const std::int16_t codes[] = {2, 256, 512, 4, 768, 8, 16, 64};
  i16(70, codes[static_cast<int>(t)]);
  i16(72, static_cast<std::int16_t>(8 * (t == ScalarType::f64                           ? 8
                                         : t == ScalarType::u8 || t == ScalarType::i8   ? 1
                                         : t == ScalarType::u16 || t == ScalarType::i16 ? 2
                                                                                        : 4)));
  const float pixdim[8] = {qform ? -1.0f : 1.0f, 0.5f, 1, 2, 1, 1, 1, 1};
  for (int a = 0; a < 8; ++a) f32(76 + 4 * a, pixdim[a]);
  f32(108, 352);
  f32(112, slope);
  f32(116, inter);
  i16(252, static_cast<std::int16_t>(qform));
  i16(254, static_cast<std::int16_t>(sform));
  for (int a = 0; a < 3; ++a) f32(268 + 4 * a, static_cast<float>(a + 1));  // qoffset 1 2 3
  const float srow[12] = {-3, 0, 0, 40, 0, 1, 0, -5, 0, 0, 2, 7};
  for (int a = 0; a < 12; ++a) f32(280 + 4 * a, srow[a]);
  h.replace(344, 4, std::string("n+1\0", 4));
  return h;
}

}  // namespace

TEST(VolumeNifti, ByteOrdersScalingAndTransforms) {
  const fs::path dir = scratch_dir();
  for (bool big : {false, true})
    for (ScalarType t : kAllTypes) {
      write(dir / "v.nii", nifti_header(t, big, 0, 0, 0, 0) + encode(t, big));
      const Volume v = read_volume(dir / "v.nii");
      expect_field(v, t, std::string(scalar_type_name(t)) + (big ? " big" : " little"));
      EXPECT_EQ(v.spacing, Vec3(0.5, 1, 2));
      EXPECT_EQ(v.origin, Vec3(0, 0, 0));
    }
  // scl_slope 2, scl_inter -5: the stored values are scaled and kept as float.
  write(dir / "s.nii", nifti_header(ScalarType::i16, true, 2, -5, 0, 0) + encode(ScalarType::i16, true));
  const Volume s = read_volume(dir / "s.nii");
  EXPECT_EQ(s.source_type, ScalarType::f32);
  EXPECT_EQ(s.at(4, 3, 2), 2 * field(4, 3, 2, ScalarType::i16) - 5);
  EXPECT_EQ(s.at(0, 0, 0), 2 * field(0, 0, 0, ScalarType::i16) - 5);
  // The sform (-3 mm along x from 40) wins over the qform: x is flipped.
  write(dir / "sf.nii", nifti_header(ScalarType::u8, false, 0, 0, 2, 1) + encode(ScalarType::u8, false));
  const Volume sf = read_volume(dir / "sf.nii");
  expect_field(
      sf, ScalarType::u8, {NX, NY, NZ},
      [](Index i, Index j, Index k) {
        return std::array<Index, 3>{NX - 1 - i, j, k};
      },
      "sform flip");
  EXPECT_EQ(sf.spacing, Vec3(3, 1, 2));
  EXPECT_EQ(sf.origin, Vec3(28, -5, 7));
  // The qform alone: identity rotation, qfac -1 (pixdim[0]) reverses z, offset (1, 2, 3).
  write(dir / "qf.nii.gz", gzip(dir, nifti_header(ScalarType::u8, false, 0, 0, 0, 1) + encode(ScalarType::u8, false)));
  const Volume qf = read_volume(dir / "qf.nii.gz");
  expect_field(
      qf, ScalarType::u8, {NX, NY, NZ},
      [](Index i, Index j, Index k) {
        return std::array<Index, 3>{i, j, NZ - 1 - k};
      },
      "qform qfac -1");
  EXPECT_EQ(qf.spacing, Vec3(0.5, 1, 2));
  EXPECT_EQ(qf.origin, Vec3(1, 2, 3 - 2 * (NZ - 1)));
}

TEST(VolumeVti, PiecesAsciiAndExtentOffset) {
  const fs::path dir = scratch_dir();
  // Two pieces split along z, a WholeExtent that starts at x = 2, ascii Int16 data.
  std::string slab0, slab1;
  for (Index k = 0; k < NZ; ++k)
    for (Index j = 0; j < NY; ++j)
      for (Index i = 0; i < NX; ++i)
        (k < 2 ? slab0 : slab1) += std::to_string(static_cast<int>(field(i, j, k, ScalarType::i16))) + " ";
  write(dir / "p.vti",
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"BigEndian\">\n"
        "<ImageData WholeExtent=\"2 6 0 3 0 2\" Origin=\"1 0 0\" Spacing=\"0.5 1 1\">\n"
        "<Piece Extent=\"2 6 0 3 0 1\"><PointData Scalars=\"s\">\n"
        "<DataArray type=\"Float32\" Name=\"other\" format=\"ascii\">" +
            std::string(120, '7') +
            "</DataArray>\n"
            "<DataArray type=\"Int16\" Name=\"s\" format=\"ascii\">" +
            slab0 +
            "</DataArray></PointData></Piece>\n"
            "<Piece Extent=\"2 6 0 3 2 2\"><PointData Scalars=\"s\">\n"
            "<DataArray type=\"Int16\" Name=\"s\" format=\"ascii\">" +
            slab1 +
            "</DataArray></PointData></Piece>\n"
            "</ImageData></VTKFile>\n");
  const Volume v = read_volume(dir / "p.vti");
  expect_field(v, ScalarType::i16, "two pieces");
  EXPECT_EQ(v.origin, Vec3(2, 0, 0));  // Origin + 2 * 0.5 along x
  EXPECT_EQ(v.spacing, Vec3(0.5, 1, 1));
}

TEST(VolumeWriters, FallBackToFloatAndKeepNonFinite) {
  const fs::path dir = scratch_dir();
  Volume v;
  v.dims = {3, 2, 2};
  v.values = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 0.5f};
  v.source_type = ScalarType::u8;  // 0.5 does not fit: written as float
  for (const char* ext : {"a.nrrd", "a.vti"}) {
    write_volume(dir / ext, v);
    const Volume back = read_volume(dir / ext);
    EXPECT_EQ(back.source_type, ScalarType::f32) << ext;
    EXPECT_EQ(back.values, v.values) << ext;
  }
  v.values[11] = std::numeric_limits<float>::quiet_NaN();
  v.values[10] = -std::numeric_limits<float>::infinity();
  v.source_type = ScalarType::f32;
  for (const char* ext : {"b.nrrd", "b.vti"}) {
    write_volume(dir / ext, v);
    const Volume back = read_volume(dir / ext);
    EXPECT_EQ(std::memcmp(back.values.data(), v.values.data(), v.values.size() * sizeof(float)), 0) << ext;
  }
  EXPECT_THROW(write_volume(dir / "a.mhd", v), Error);
  v.spacing.x() = 0;
  EXPECT_THROW(write_volume(dir / "c.nrrd", v), Error);
  EXPECT_FALSE(fs::exists(dir / "c.nrrd"));
}
