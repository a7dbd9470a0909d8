// Lying and broken headers: every one must give an isohex::Error that names the file and
// the field at fault, never a crash or a huge allocation; oversized volumes are refused
// before anything is allocated.
#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/volume/volume_io.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>

using namespace isohex;
using isohex::test::scratch_dir;
namespace fs = std::filesystem;

namespace {

void write(const fs::path& file, const std::string& bytes) { std::ofstream(file, std::ios::binary) << bytes; }

/// Expects read_volume(file) to throw isohex::Error mentioning the file name and each part.
void expect_error(const fs::path& file, const std::vector<std::string>& parts, VolumeReadOptions options = {}) {
  try {
    read_volume(file, options);
    ADD_FAILURE() << "no error reading " << file.filename();
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(file.filename().string()), std::string::npos) << m;
    for (const std::string& p : parts) EXPECT_NE(m.find(p), std::string::npos) << "'" << p << "' missing from: " << m;
  }
}

std::string gzip_of(const fs::path& dir, const std::string& bytes) {
  write(dir / "in.bin", bytes);
  EXPECT_EQ(std::system(("gzip -c '" + (dir / "in.bin").string() + "' > '" + (dir / "in.gz").string() + "'").c_str()),
            0);
  return io::read_file(dir / "in.gz");
}

const std::string kData(60, '\x07');  // 5 x 4 x 3 u8 values

std::string nrrd(const std::string& fields) { return "NRRD0004\n" + fields; }

std::string nifti(std::int16_t datatype, std::int16_t bitpix, std::int16_t nx, std::int16_t dim4 = 1, float vox = 352) {
  std::string h(352, '\0');
  auto put = [&](std::size_t at, const void* p, std::size_t n) { h.replace(at, n, static_cast<const char*>(p), n); };
  const std::int32_t size = 348;
  put(0, &size, 4);
  const std::int16_t dim[8] = {static_cast<std::int16_t>(dim4 > 1 ? 4 : 3), nx, 4, 3, dim4, 1, 1, 1};
  put(40, dim, 16);
  put(70, &datatype, 2);
  put(72, &bitpix, 2);
  const float pixdim[8] = {1, 1, 1, 1, 1, 1, 1, 1};
  put(76, pixdim, 32);
  put(108, &vox, 4);
  put(344, "n+1\0", 4);
  return h;
}

}  // namespace

TEST(VolumeErrors, NrrdHeaders) {
  const fs::path d = scratch_dir();
  const std::string ok = "type: uchar\ndimension: 3\nencoding: raw\n";
  struct Case {
    std::string name, text;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases = {
      {"neg.nrrd", nrrd(ok + "sizes: -5 4 3\n\n") + kData, {"field 'sizes'", "positive"}},
      {"zero.nrrd", nrrd(ok + "sizes: 5 0 3\n\n") + kData, {"field 'sizes'", "positive"}},
      {"huge.nrrd", nrrd(ok + "sizes: 3000000000 1 1\n\n") + kData, {"field 'sizes'", "limit"}},
      {"few.nrrd", nrrd(ok + "sizes: 5 4\n\n") + kData, {"field 'sizes'", "3 sizes"}},
      {"type.nrrd", nrrd("type: quaternion\ndimension: 3\nencoding: raw\nsizes: 5 4 3\n\n") + kData, {"field 'type'"}},
      {"int64.nrrd", nrrd("type: int64\ndimension: 3\nencoding: raw\nsizes: 5 4 3\n\n") + kData, {"field 'type'"}},
      {"dim.nrrd", nrrd("type: uchar\ndimension: 4\nencoding: raw\nsizes: 5 4 3 1\n\n") + kData, {"field 'dimension'"}},
      {"endian.nrrd",
       nrrd("type: short\ndimension: 3\nencoding: raw\nsizes: 5 4 3\n\n") + kData + kData,
       {"field 'endian'"}},
      {"enc.nrrd", nrrd("type: uchar\ndimension: 3\nencoding: bzip2\nsizes: 5 4 3\n\n") + kData, {"field 'encoding'"}},
      {"short.nrrd", nrrd(ok + "sizes: 5 4 4\n\n") + kData, {"truncated, or the header lies"}},
      {"dirs.nrrd",
       nrrd(ok + "sizes: 5 4 3\nspace directions: none (0,1,0) (0,0,1)\n\n") + kData,
       {"field 'space directions'"}},
      {"spacing.nrrd", nrrd(ok + "sizes: 5 4 3\nspacings: 1 0 1\n\n") + kData, {"field 'spacings'", "positive"}},
      {"magic.nrrd", "P5\n5 4\n255\n" + kData, {"line 1", "NRRD"}},
      {"nodata.nhdr", nrrd(ok + "sizes: 5 4 3\ndata file: nowhere.raw\n"), {"field 'data file'", "does not exist"}},
      {"sizes.nrrd", nrrd("type: uchar\ndimension: 3\nencoding: raw\n\n") + kData, {"field 'sizes'", "missing"}},
  };
  for (const Case& c : cases) {
    write(d / c.name, c.text);
    expect_error(d / c.name, c.parts);
  }
  // A product of sizes that overflows 64 bits, even with no memory limit.
  write(d / "overflow.nrrd", nrrd(ok + "sizes: 2000000000 2000000000 2000000000\n\n"));
  VolumeReadOptions unlimited;
  unlimited.max_bytes = std::numeric_limits<std::size_t>::max();
  expect_error(d / "overflow.nrrd", {"field 'sizes'", "overflow"}, unlimited);
}

TEST(VolumeErrors, CompressedData) {
  const fs::path d = scratch_dir();
  const std::string gz = gzip_of(d, std::string(6000, 'x') + kData);
  const std::string head = nrrd("type: uchar\ndimension: 3\nencoding: gzip\nsizes: 5 4 303\n\n");
  write(d / "cut.nrrd", head + gz.substr(0, gz.size() / 2));
  expect_error(d / "cut.nrrd", {"gzip data", "truncated"});
  std::string bad = gz;
  bad[0] = 'x';  // neither a gzip nor a zlib header
  write(d / "bad.nrrd", head + bad);
  expect_error(d / "bad.nrrd", {"gzip data", "corrupt"});
  // Complete gzip data that holds less than the sizes need.
  write(d / "less.nrrd", nrrd("type: uchar\ndimension: 3\nencoding: gzip\nsizes: 5 4 400\n\n") + gz);
  expect_error(d / "less.nrrd", {"short of the"});
  // A truncated .nii.gz: the header inflates, the voxels end early.
  std::string voxels;
  for (int i = 0; i < 6000; ++i) voxels += static_cast<char>((i * 7919) % 251);
  const std::string nii_gz = gzip_of(d, nifti(2, 8, 500) + voxels);
  write(d / "cut.nii.gz", nii_gz.substr(0, nii_gz.size() - 100));
  expect_error(d / "cut.nii.gz", {"gzip data", "truncated"});
}

TEST(VolumeErrors, MetaImageHeaders) {
  const fs::path d = scratch_dir();
  const std::string base = "NDims = 3\nElementType = MET_UCHAR\n";
  write(d / "dims.mha", base + "DimSize = 5 -4 3\nElementDataFile = LOCAL\n" + kData);
  expect_error(d / "dims.mha", {"DimSize", "positive"});
  write(d / "type.mha", "NDims = 3\nDimSize = 5 4 3\nElementType = MET_FOO\nElementDataFile = LOCAL\n" + kData);
  expect_error(d / "type.mha", {"ElementType", "MET_FOO"});
  write(d / "ndims.mha", "NDims = 2\nDimSize = 5 4\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n" + kData);
  expect_error(d / "ndims.mha", {"NDims"});
  write(d / "missing.mhd", base + "DimSize = 5 4 3\nElementDataFile = gone.raw\n");
  expect_error(d / "missing.mhd", {"ElementDataFile", "gone.raw", "does not exist"});
  write(d / "short.mha", base + "DimSize = 5 4 30\nElementDataFile = LOCAL\n" + kData);
  expect_error(d / "short.mha", {"truncated, or the header lies"});
  write(d / "noend.mha", base + "DimSize = 5 4 3\n");
  expect_error(d / "noend.mha", {"ElementDataFile", "missing"});
  write(d / "chan.mha", base + "DimSize = 5 4 3\nElementNumberOfChannels = 3\nElementDataFile = LOCAL\n" + kData);
  expect_error(d / "chan.mha", {"ElementNumberOfChannels"});
}

TEST(VolumeErrors, LegacyVtkHeaders) {
  const fs::path d = scratch_dir();
  const std::string head = "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\n";
  write(d / "neg.vtk", head + "DIMENSIONS 5 4 -3\nPOINT_DATA 60\nSCALARS s unsigned_char\n" + kData);
  expect_error(d / "neg.vtk", {"DIMENSIONS", "positive"});
  write(d / "count.vtk", head + "DIMENSIONS 5 4 3\nPOINT_DATA 61\nSCALARS s unsigned_char\n" + kData);
  expect_error(d / "count.vtk", {"POINT_DATA 61", "DIMENSIONS"});
  write(d / "type.vtk", head + "DIMENSIONS 5 4 3\nPOINT_DATA 60\nSCALARS s quux\n" + kData);
  expect_error(d / "type.vtk", {"SCALARS", "quux"});
  write(d / "long.vtk", head + "DIMENSIONS 5 4 3\nPOINT_DATA 60\nSCALARS s vtktypeint64\n" + kData);
  expect_error(d / "long.vtk", {"SCALARS", "not supported"});
  write(d / "short.vtk", head + "DIMENSIONS 5 4 3\nPOINT_DATA 60\nSCALARS s float\nLOOKUP_TABLE default\n" + kData);
  expect_error(d / "short.vtk", {"binary SCALARS", "truncated"});
  write(d / "grid.vtk", "# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 0 float\n");
  expect_error(d / "grid.vtk", {"line 4", "STRUCTURED_POINTS"});
}

TEST(VolumeErrors, NiftiHeaders) {
  const fs::path d = scratch_dir();
  write(d / "complex.nii", nifti(32, 64, 5) + std::string(480, '\0'));
  expect_error(d / "complex.nii", {"datatype", "complex64"});
  write(d / "dim.nii", nifti(2, 8, -5) + kData);
  expect_error(d / "dim.nii", {"dim", "positive"});
  write(d / "bitpix.nii", nifti(4, 8, 5) + kData + kData);
  expect_error(d / "bitpix.nii", {"bitpix"});
  write(d / "short.nii", nifti(2, 8, 50) + kData);
  expect_error(d / "short.nii", {"dim", "truncated, or the header lies"});
  write(d / "series.nii", nifti(2, 8, 5, 7) + kData);
  expect_error(d / "series.nii", {"dim[4]"});
  write(d / "offset.nii", nifti(2, 8, 5, 1, 100.5f) + kData);
  expect_error(d / "offset.nii", {"vox_offset"});
  std::string bad = nifti(2, 8, 5) + kData;
  bad[0] = 7;
  write(d / "hdr.nii", bad);
  expect_error(d / "hdr.nii", {"sizeof_hdr"});
  write(d / "tiny.nii", "abc");
  expect_error(d / "tiny.nii", {"header", "348"});
}

TEST(VolumeErrors, VtiHeadersAndData) {
  const fs::path d = scratch_dir();
  const auto vti = [](const std::string& whole, const std::string& type, const std::string& data) {
    return "<VTKFile type=\"ImageData\" version=\"1.0\"><ImageData WholeExtent=\"" + whole + "\"><Piece Extent=\"" +
           whole + "\"><PointData><DataArray type=\"" + type + "\" format=\"ascii\">" + data +
           "</DataArray></PointData></Piece></ImageData></VTKFile>\n";
  };
  write(d / "empty.vti", vti("0 -1 0 3 0 2", "UInt8", "1"));
  expect_error(d / "empty.vti", {"WholeExtent", "positive"});
  write(d / "words.vti", vti("0 a 0 3 0 2", "UInt8", "1"));
  expect_error(d / "words.vti", {"WholeExtent", "6 integers"});
  write(d / "type.vti", vti("0 0 0 0 0 0", "Quux", "1"));
  expect_error(d / "type.vti", {"type", "Quux"});
  write(d / "few.vti", vti("0 1 0 1 0 1", "UInt8", "1 2 3"));
  expect_error(d / "few.vti", {"DataArray", "8 values", "at most 3"});
  write(d / "grid.vti", "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid/></VTKFile>");
  expect_error(d / "grid.vti", {"UnstructuredGrid", "ImageData"});
  // Appended binary data cut short.
  Volume v;
  v.dims = {10, 10, 10};
  v.values.assign(1000, 1.5f);
  write_volume(d / "cut.vti", v);
  const std::string text = io::read_file(d / "cut.vti");
  write(d / "cut.vti", text.substr(0, text.size() - 2000));
  expect_error(d / "cut.vti", {"values", "truncated"});
}

TEST(VolumeErrors, RawLayoutAndFormatChoice) {
  const fs::path d = scratch_dir();
  write(d / "v.raw", kData);
  VolumeReadOptions opt;
  opt.raw = RawLayout{};
  opt.raw->dims = {5, 4, 4};
  expect_error(d / "v.raw", {"raw layout", "60 bytes", "need 80"}, opt);
  opt.raw->dims = {5, 4, 3};
  opt.raw->spacing = Vec3(1, -1, 1);
  expect_error(d / "v.raw", {"raw layout spacing", "positive"}, opt);
  expect_error(d / "v.raw", {"--dims", "--type"});
  write(d / "v.xyz", kData);
  expect_error(d / "v.xyz", {"unknown volume format"});
  expect_error(d / "absent.nrrd", {"cannot open"});
}

TEST(VolumeErrors, MemoryLimitRefusesBeforeAllocating) {
  const fs::path d = scratch_dir();
  // 10^15 declared points (4 PB as float) and no data: refused at once, from each format.
  write(d / "big.nrrd", nrrd("type: uchar\ndimension: 3\nencoding: raw\nsizes: 100000 100000 100000\n\n"));
  write(d / "big.mha", "NDims = 3\nDimSize = 100000 100000 100000\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n");
  write(d / "big.vtk",
        "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 100000 100000 "
        "100000\nPOINT_DATA 1000000000000000\nSCALARS s unsigned_char\n");
  write(d / "big.vti",
        "<VTKFile type=\"ImageData\"><ImageData WholeExtent=\"0 99999 0 99999 0 99999\"><Piece "
        "Extent=\"0 99999 0 99999 0 99999\"><PointData><DataArray type=\"UInt8\" format=\"ascii\">1"
        "</DataArray></PointData></Piece></ImageData></VTKFile>");
  write(d / "big.nii", nifti(2, 8, 30000) + kData);  // 30000 x 4 x 3 fits int16; limit set below
  const auto start = std::chrono::steady_clock::now();
  for (const char* f : {"big.nrrd", "big.mha", "big.vtk", "big.vti"}) expect_error(d / f, {"limit", "--max-memory"});
  VolumeReadOptions small;
  small.max_bytes = 1000;
  expect_error(d / "big.nii", {"dim", "limit of 1000 bytes"}, small);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  // A real file over a small limit is refused too.
  write(d / "ok.nrrd", nrrd("type: uchar\ndimension: 3\nencoding: raw\nsizes: 5 4 3\n\n") + kData);
  small.max_bytes = 239;  // 60 floats need 240 bytes
  expect_error(d / "ok.nrrd", {"240 bytes", "limit of 239"}, small);
  small.max_bytes = 240;
  EXPECT_EQ(read_volume(d / "ok.nrrd", small).size(), 60u);
}
