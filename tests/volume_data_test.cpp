// The shared test volumes: each loads with the dimensions and statistics SOURCES.md states,
// the derived raw files equal their originals' decoding, and every volume survives a round
// trip through .nrrd and .vti bit for bit.
#include "isohex/io/atomic_file.hpp"
#include "isohex/volume/statistics.hpp"
#include "isohex/volume/volume_io.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <fstream>

using namespace isohex;
using isohex::test::scratch_dir;
using isohex::test::shared_data;
namespace fs = std::filesystem;

namespace {

fs::path vol(const std::string& name) { return shared_data("volumes/" + name); }

RawLayout raw(Index nx, Index ny, Index nz, ScalarType type, bool big_endian = false) {
  RawLayout r;
  r.dims = {nx, ny, nz};
  r.type = type;
  r.big_endian = big_endian;
  return r;
}

Volume read_raw(const std::string& name, const RawLayout& layout) {
  VolumeReadOptions opt;
  opt.raw = layout;
  return read_volume(vol(name), opt);
}

void write_text(const fs::path& file, const std::string& text) { std::ofstream(file, std::ios::binary) << text; }

/// Values compared bit for bit (NaN-safe), and the geometry exactly.
void expect_identical(const Volume& a, const Volume& b, const std::string& what) {
  EXPECT_EQ(a.dims, b.dims) << what;
  EXPECT_EQ(a.spacing, b.spacing) << what;
  EXPECT_EQ(a.origin, b.origin) << what;
  ASSERT_EQ(a.values.size(), b.values.size()) << what;
  EXPECT_EQ(std::memcmp(a.values.data(), b.values.data(), a.values.size() * sizeof(float)), 0) << what;
}

struct Expected {
  std::string file;
  std::optional<RawLayout> layout;
  std::array<Index, 3> dims;
  double min, max, mean, mean_tolerance;
};

}  // namespace

TEST(VolumeData, EveryVolumeMatchesSources) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const std::vector<Expected> cases = {
      {"cthead_256x256x113_int16be.raw",
       raw(256, 256, 113, ScalarType::i16, true),
       {256, 256, 113},
       0,
       3272,
       379.5421,
       5e-5},
      {"headsq_64x64x93_int16le.raw", raw(64, 64, 93, ScalarType::i16), {64, 64, 93}, 0, 3926, 507.6873, 5e-5},
      {"HeadMRVolume.mhd", std::nullopt, {48, 62, 42}, 0, 255, 24.4682, 5e-5},
      {"avg152T1_RL_nifti.nii.gz", std::nullopt, {91, 109, 91}, 0, 255, 82.8972, 5e-5},
      {"bucky_32x32x32_uint8.raw", raw(32, 32, 32, ScalarType::u8), {32, 32, 32}, 0, 255, 35.8498, 5e-5},
      {"ironProt.vtk", std::nullopt, {68, 68, 68}, 0, 255, 13.1383, 5e-5},
      {"neghip_66x66x66_uint8.raw", raw(66, 66, 66, ScalarType::u8), {66, 66, 66}, 0, 255, 16.7800, 5e-5},
      {"hydrogen.vti", std::nullopt, {64, 64, 64}, 0, 1, 0.0185242, 5e-8},
      {"hydrogen_64x64x64_float32le.raw", raw(64, 64, 64, ScalarType::f32), {64, 64, 64}, 0, 1, 0.0185242, 5e-8},
  };
  for (const Expected& e : cases) {
    VolumeReadOptions opt;
    opt.raw = e.layout;
    const Volume v = read_volume(vol(e.file), opt);
    EXPECT_EQ(v.dims, e.dims) << e.file;
    const ValueStatistics s = value_statistics(v);
    EXPECT_EQ(s.count, v.size()) << e.file;
    EXPECT_EQ(s.min, e.min) << e.file;
    EXPECT_EQ(s.max, e.max) << e.file;
    EXPECT_NEAR(s.mean, e.mean, e.mean_tolerance) << e.file;
  }
}

TEST(VolumeData, HeaderGeometryAndTypes) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const Volume mr = read_volume(vol("HeadMRVolume.mhd"));
  EXPECT_EQ(mr.spacing, Vec3(4, 4, 4));
  EXPECT_EQ(mr.source_type, ScalarType::u8);
  const Volume iron = read_volume(vol("ironProt.vtk"));
  EXPECT_EQ(iron.spacing, Vec3(1, 1, 1));
  EXPECT_EQ(iron.origin, Vec3(0, 0, 0));
  const Volume h = read_volume(vol("hydrogen.vti"));
  EXPECT_EQ(h.source_type, ScalarType::f32);
  // The MNI template's sform (code 4): 2 mm steps from (-90, -126, -72).
  const Volume mni = read_volume(vol("avg152T1_RL_nifti.nii.gz"));
  EXPECT_EQ(mni.spacing, Vec3(2, 2, 2));
  EXPECT_EQ(mni.origin, Vec3(-90, -126, -72));
  EXPECT_EQ(mni.max_corner(), Vec3(90, 90, 108));
}

TEST(VolumeData, HydrogenVtiEqualsDerivedRaw) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const Volume a = read_volume(vol("hydrogen.vti"));
  const Volume b = read_raw("hydrogen_64x64x64_float32le.raw", raw(64, 64, 64, ScalarType::f32));
  expect_identical(a, b, "hydrogen");
}

TEST(VolumeData, IronProtEqualsItsBytes) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const Volume v = read_volume(vol("ironProt.vtk"));
  const std::string bytes = io::read_file(vol("ironProt.vtk"));
  ASSERT_EQ(bytes.size(), 209u + v.size() + 1);
  for (std::size_t i = 0; i < v.size(); ++i) ASSERT_EQ(v.values[i], static_cast<unsigned char>(bytes[209 + i])) << i;
}

TEST(VolumeData, HeadMrMhdEqualsItsRawFile) {
  ISOHEX_REQUIRE_SHARED_DATA();
  Volume a = read_volume(vol("HeadMRVolume.mhd"));
  const Volume b = read_raw("HeadMRVolume.raw", raw(48, 62, 42, ScalarType::u8));
  a.spacing = b.spacing;  // the raw read has unit spacing
  expect_identical(a, b, "HeadMRVolume");
}

TEST(VolumeData, NiftiGzipAndDecompressedCopyAgree) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  const fs::path nii = dir / "avg152.nii";
  ASSERT_EQ(
      std::system(("gzip -dc '" + vol("avg152T1_RL_nifti.nii.gz").string() + "' > '" + nii.string() + "'").c_str()), 0);
  const Volume gz = read_volume(vol("avg152T1_RL_nifti.nii.gz"));
  const Volume plain = read_volume(nii);
  expect_identical(gz, plain, "avg152 .nii.gz vs .nii");
  // Against the bytes after vox_offset 352.
  const std::string bytes = io::read_file(nii);
  ASSERT_EQ(bytes.size(), 352u + 91 * 109 * 91);
  for (Index k = 0; k < 91; ++k)
    for (Index j = 0; j < 109; ++j)
      for (Index i = 0; i < 91; ++i)
        ASSERT_EQ(plain.at(i, j, k), static_cast<unsigned char>(bytes[352 + i + 91 * (j + 109 * k)]));
}

TEST(VolumeData, DetachedNrrdHeadersOverTheRawFiles) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  // headsq quarter as VTK's own quarter.nhdr describes it, pointing at the derived raw file.
  write_text(dir / "headsq.nhdr",
             "NRRD0004\ntype: short\ndimension: 3\nspace: 3D-left-handed\nsizes: 64 64 93\n"
             "spacings: 3.2 3.2 1.5\nendian: little\nencoding: raw\ndata file: " +
                 vol("headsq_64x64x93_int16le.raw").string() + "\n");
  const Volume headsq = read_volume(dir / "headsq.nhdr");
  EXPECT_EQ(headsq.spacing, Vec3(3.2, 3.2, 1.5));
  Volume ref = read_raw("headsq_64x64x93_int16le.raw", raw(64, 64, 93, ScalarType::i16));
  ref.spacing = headsq.spacing;
  expect_identical(headsq, ref, "headsq.nhdr");
  EXPECT_EQ(headsq.source_type, ScalarType::i16);

  // The same data as VTK ships it: one file per slice, named by a %d series.
  const std::string bytes = io::read_file(vol("headsq_64x64x93_int16le.raw"));
  for (int s = 1; s <= 93; ++s)
    write_text(dir / ("quarter." + std::to_string(s)), bytes.substr(static_cast<std::size_t>(s - 1) * 8192, 8192));
  write_text(dir / "quarter.nhdr",
             "NRRD0004\ntype: short\ndimension: 3\nsizes: 64 64 93\nspacings: 3.2 3.2 1.5\n"
             "endian: little\nencoding: raw\ndata file: quarter.%d 1 93 1\n");
  expect_identical(read_volume(dir / "quarter.nhdr"), ref, "quarter.%d series");

  // cthead is big-endian; a relative data file name resolves next to the header.
  fs::copy_file(vol("cthead_256x256x113_int16be.raw"), dir / "cthead.raw");
  write_text(dir / "cthead.nhdr",
             "NRRD0005\n# comment\ntype: int16\ndimension: 3\nsizes: 256 256 113\n"
             "endian: big\nencoding: raw\nmeta:=data\ndata file: cthead.raw\n");
  expect_identical(read_volume(dir / "cthead.nhdr"),
                   read_raw("cthead_256x256x113_int16be.raw", raw(256, 256, 113, ScalarType::i16, true)),
                   "cthead.nhdr");

  // gzip-encoded data (compressed here by gzip itself) behind a detached header.
  ASSERT_EQ(std::system(("gzip -c '" + vol("bucky_32x32x32_uint8.raw").string() + "' > '" +
                         (dir / "bucky.raw.gz").string() + "'")
                            .c_str()),
            0);
  write_text(dir / "bucky.nhdr",
             "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 32 32 32\nencoding: gzip\n"
             "data file: bucky.raw.gz\n");
  expect_identical(read_volume(dir / "bucky.nhdr"),
                   read_raw("bucky_32x32x32_uint8.raw", raw(32, 32, 32, ScalarType::u8)), "bucky gzip");
}

TEST(VolumeData, RoundTripsThroughNrrdAndVtiAreBitExact) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  std::vector<std::pair<std::string, Volume>> volumes;
  volumes.emplace_back("cthead", read_raw("cthead_256x256x113_int16be.raw", raw(256, 256, 113, ScalarType::i16, true)));
  volumes.emplace_back("mr", read_volume(vol("HeadMRVolume.mhd")));
  volumes.emplace_back("mni", read_volume(vol("avg152T1_RL_nifti.nii.gz")));
  volumes.emplace_back("iron", read_volume(vol("ironProt.vtk")));
  volumes.emplace_back("hydrogen", read_volume(vol("hydrogen.vti")));
  for (auto& [name, v] : volumes) {
    v.origin = Vec3(-12.345678901234567, 0.1, 1e-7);  // digits that need %.17g to survive
    v.spacing.x() = 0.3;
    for (const char* ext : {".nrrd", ".vti"}) {
      const fs::path file = dir / (name + ext);
      write_volume(file, v);
      const Volume back = read_volume(file);
      expect_identical(back, v, name + ext);
      EXPECT_EQ(back.source_type, v.source_type) << name << ext;
    }
  }
  // The integer source type is kept on disk: cthead as int16 is 2 bytes a value.
  EXPECT_LT(fs::file_size(dir / "cthead.nrrd"), 256u * 256 * 113 * 2 + 1000);
}
