#include "test_support.hpp"

#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/generate.hpp"
#include "isohex/volume/volume_io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

namespace isohex::test {

namespace fs = std::filesystem;

bool have_shared_data() { return fs::is_directory(ISOHEX_SHARED_DATA); }

fs::path shared_data(const std::string& rel) {
  return fs::path(ISOHEX_SHARED_DATA) / rel;
}

Volume shared_volume(const std::string& file) {
  VolumeReadOptions opt;
  RawLayout raw;
  if (file == "cthead_256x256x113_int16be.raw") {
    raw.dims = {256, 256, 113};
    raw.type = ScalarType::i16;
    raw.big_endian = true;
    raw.spacing = Vec3(1, 1, 2);  // not stated in the source; the project's assumption
    opt.raw = raw;
  } else if (file == "headsq_64x64x93_int16le.raw") {
    raw.dims = {64, 64, 93};
    raw.type = ScalarType::i16;
    raw.spacing = Vec3(3.2, 3.2, 1.5);
    opt.raw = raw;
  } else if (file == "bucky_32x32x32_uint8.raw") {
    raw.dims = {32, 32, 32};
    raw.type = ScalarType::u8;
    opt.raw = raw;
  }
  return read_volume(shared_data("volumes/" + file), opt);
}

Volume block_volume(Index n, const std::vector<std::pair<std::array<Index, 3>, float>>& set) {
  Volume v;
  v.dims = {n, n, n};
  v.values.assign(v.size(), 0.0f);
  for (Index z = 1; z < 7; ++z)
    for (Index y = 1; y < 7; ++y)
      for (Index x = 1; x < 7; ++x) v.at(x, y, z) = 1.0f;
  for (const auto& [p, value] : set) v.at(p[0], p[1], p[2]) = value;
  return v;
}

std::array<Vec3, 8> unit_cube() {
  return {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0),
          Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(1, 1, 1), Vec3(0, 1, 1)};
}

fs::path scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  fs::path dir = fs::path(ISOHEX_TEST_TMP) / (std::string(info->test_suite_name()) + "." + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

HexMesh read_piece(const std::string& name, std::vector<Index>& targets, bool boundary_free) {
  std::ifstream in(std::string(ISOHEX_TEST_DATA) + "/" + name);
  EXPECT_TRUE(in) << name;
  HexMesh m;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      Vec3 p;
      int role = 0;
      s >> p.x() >> p.y() >> p.z() >> role;
      m.points.push_back(p);
      m.fixed.push_back(role == 1 || (role == 2 && boundary_free) ? 0 : 1);
    } else if (tag == "h") {
      Hex h;
      for (Index& v : h) s >> v;
      m.hexes.push_back(h);
    } else if (tag == "t") {
      for (Index t; s >> t;) targets.push_back(t);
    }
  }
  return m;
}

WorstResult stall_single_moves(HexMesh& m, int passes) {
  WorstOptions single;
  single.patch_rounds = 0;
  single.search_trials = 0;
  single.passes = passes;
  single.stall_passes = 0;  // until no single move gains, not until they gain little
  return improve_worst(m, m.fixed, single);
}

std::size_t smooth_piece_count(const std::string& name, const std::string& extra, const std::string& key) {
  const auto dir = scratch_dir() / "piece";
  std::filesystem::create_directories(dir);
  std::vector<Index> targets;
  io::write_mesh(dir / "in.vtu", read_piece(name, targets, true));
  std::string out;
  const int rc = run_cli("smooth " + quote(dir / "in.vtu") + " -o " + quote(dir / "out.vtu") +
                             " --fixed file --max-iter 0 --json " + quote(dir / "r.json") + extra,
                         &out);
  EXPECT_EQ(rc, 0) << out;
  std::ifstream in(dir / "r.json");
  return nlohmann::json::parse(in)["worst"][key].get<std::size_t>();
}

void expect_smooth_refuses(const std::string& name, const std::string& option, const std::string& value) {
  const auto dir = scratch_dir() / "refused";
  std::filesystem::create_directories(dir);
  std::vector<Index> targets;
  io::write_mesh(dir / "in.vtu", read_piece(name, targets, true));
  std::string out;
  EXPECT_EQ(run_cli("smooth " + quote(dir / "in.vtu") + " -o " + quote(dir / "bad.vtu") + " " + option + " " + value, &out), 2)
      << out;
  EXPECT_NE(out.find(option), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.vtu"));
}

HexMesh grid_mesh(int nx, int ny, int nz, double h) {
  return box_mesh(nx, ny, nz, Vec3::Zero(), Vec3(nx * h, ny * h, nz * h));
}

std::string quote(const fs::path& path) { return "'" + path.string() + "'"; }

int run_cli(const std::string& args, std::string* output) {
  const std::string cmd = std::string(ISOHEX_CLI) + " " + args + " 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buf{};
  std::string out;
  while (size_t n = std::fread(buf.data(), 1, buf.size(), pipe)) out.append(buf.data(), n);
  const int status = ::pclose(pipe);
  if (output) *output = out;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace isohex::test
