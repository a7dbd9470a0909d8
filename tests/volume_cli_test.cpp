// `isohex volume info|convert` end to end: the report and its JSON, conversions, raw
// layout options, the memory limit and the exit code for bad input.
#include "isohex/io/atomic_file.hpp"
#include "isohex/volume/volume_io.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstring>
#include <fstream>

using namespace isohex;
using isohex::test::run_cli;
using isohex::test::scratch_dir;
using isohex::test::shared_data;
namespace fs = std::filesystem;

namespace {
std::string q(const fs::path& p) { return "'" + p.string() + "'"; }
}  // namespace

TEST(VolumeCli, InfoReportsStatisticsAndJson) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  std::string out;
  ASSERT_EQ(run_cli("volume info " + q(shared_data("volumes/headsq_64x64x93_int16le.raw")) +
                        " --dims 64 64 93 --type i16 --spacing 3.2 3.2 1.5 --origin 1 2 3 --json " + q(dir / "i.json"),
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("64 x 64 x 93"), std::string::npos) << out;
  EXPECT_NE(out.find("Otsu"), std::string::npos) << out;
  const auto j = nlohmann::json::parse(io::read_file(dir / "i.json"));
  EXPECT_EQ(j["dims"], nlohmann::json({64, 64, 93}));
  EXPECT_EQ(j["spacing"], nlohmann::json({3.2, 3.2, 1.5}));
  EXPECT_EQ(j["origin"], nlohmann::json({1.0, 2.0, 3.0}));
  EXPECT_EQ(j["source_type"], "i16");
  EXPECT_EQ(j["min"], 0.0);
  EXPECT_EQ(j["max"], 3926.0);
  EXPECT_NEAR(j["mean"].get<double>(), 507.6873, 5e-5);
  std::size_t total = 0;
  for (const auto& c : j["histogram"]["counts"]) total += c.get<std::size_t>();
  EXPECT_EQ(total, 64u * 64 * 93);
  EXPECT_EQ(j["histogram"]["edges"].size(), j["histogram"]["counts"].size() + 1);
  // Otsu separates background from head: somewhere inside the value range.
  EXPECT_GT(j["otsu_isovalue"].get<double>(), 100);
  EXPECT_LT(j["otsu_isovalue"].get<double>(), 3000);
}

TEST(VolumeCli, ConvertToNrrdAndVti) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  std::string out;
  ASSERT_EQ(run_cli("volume convert " + q(shared_data("volumes/cthead_256x256x113_int16be.raw")) + " " +
                        q(dir / "ct.nrrd") + " --dims 256 256 113 --type i16 --endian big --spacing 1 1 2",
                    &out),
            0)
      << out;
  ASSERT_EQ(run_cli("volume convert " + q(dir / "ct.nrrd") + " " + q(dir / "ct.vti"), &out), 0) << out;
  ASSERT_EQ(run_cli("volume convert " + q(dir / "ct.vti") + " " + q(dir / "ctf.nrrd") + " --float", &out), 0) << out;
  VolumeReadOptions opt;
  opt.raw = RawLayout{};
  opt.raw->dims = {256, 256, 113};
  opt.raw->type = ScalarType::i16;
  opt.raw->big_endian = true;
  const Volume ref = read_volume(shared_data("volumes/cthead_256x256x113_int16be.raw"), opt);
  for (const char* f : {"ct.nrrd", "ct.vti", "ctf.nrrd"}) {
    const Volume v = read_volume(dir / f);
    EXPECT_EQ(v.dims, ref.dims) << f;
    EXPECT_EQ(v.spacing, Vec3(1, 1, 2)) << f;
    EXPECT_EQ(v.values, ref.values) << f;
    EXPECT_EQ(v.source_type, std::strcmp(f, "ctf.nrrd") == 0 ? ScalarType::f32 : ScalarType::i16) << f;
  }
}

TEST(VolumeCli, BadInputExitsWithTwoAndNamesTheFault) {
  const fs::path dir = scratch_dir();
  std::string out;
  { std::ofstream(dir / "lie.nrrd") << "NRRD0004\ntype: uchar\ndimension: 3\nencoding: raw\nsizes: 4 4 -4\n\n"; }
  EXPECT_EQ(run_cli("volume info " + q(dir / "lie.nrrd"), &out), 2);
  EXPECT_NE(out.find("lie.nrrd: field 'sizes'"), std::string::npos) << out;
  {
    std::ofstream(dir / "ok.nrrd") << "NRRD0004\ntype: uchar\ndimension: 3\nencoding: raw\nsizes: 64 64 64\n\n"
                                   << std::string(64 * 64 * 64, 'a');
  }
  EXPECT_EQ(run_cli("volume info " + q(dir / "ok.nrrd") + " --max-memory 1MiB", &out), 0) << out;
  EXPECT_EQ(run_cli("volume info " + q(dir / "ok.nrrd") + " --max-memory 1000KiB", &out), 2) << out;
  EXPECT_NE(out.find("limit of 1024000 bytes"), std::string::npos) << out;
  EXPECT_NE(run_cli("volume info " + q(dir / "ok.nrrd") + " --dims 4 4", &out), 0) << out;  // 3 values needed
  EXPECT_EQ(run_cli("volume convert " + q(dir / "ok.nrrd") + " " + q(dir / "x.mha"), &out), 2) << out;
  EXPECT_NE(out.find("writable: .nrrd .vti"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir / "x.mha"));
  EXPECT_EQ(run_cli("volume info " + q(dir / "ok.raw") + " --type u8", &out), 2) << out;
  EXPECT_NE(out.find("--dims"), std::string::npos) << out;
}
