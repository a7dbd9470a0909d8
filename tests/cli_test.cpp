// The CLI end to end: generate → check → quality → convert, exit codes, outputs.
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sstream>

using namespace isohex;
using isohex::test::run_cli;
using isohex::test::scratch_dir;
constexpr auto q = isohex::test::quote;

TEST(Cli, HelpListsEverySubcommand) {
  std::string out;
  EXPECT_EQ(run_cli("--help", &out), 0);
  for (const char* sub : {"quality", "check", "convert", "generate"}) EXPECT_NE(out.find(sub), std::string::npos) << sub;
  for (const char* sub : {"quality", "check", "convert", "generate"}) {
    EXPECT_EQ(run_cli(std::string(sub) + " --help", &out), 0) << sub;
    EXPECT_NE(out.find("Usage"), std::string::npos);
  }
}

TEST(Cli, BoxIsValidAndPerfect) {
  const auto dir = scratch_dir();
  std::string out;
  ASSERT_EQ(run_cli("generate box -n 4 -o " + q(dir / "box.vtu"), &out), 0) << out;
  EXPECT_EQ(run_cli("check " + q(dir / "box.vtu"), &out), 0) << out;
  EXPECT_NE(out.find("VALID"), std::string::npos);
  ASSERT_EQ(run_cli("quality " + q(dir / "box.vtu") + " --json " + q(dir / "q.json"), &out), 0) << out;
  const auto j = nlohmann::json::parse(io::read_file(dir / "q.json"));
  EXPECT_EQ(j["hexes"], 64);
  EXPECT_EQ(j["boundary_quads"], 96);
  EXPECT_EQ(j["metrics"]["scaled_jacobian"]["min"], 1.0);
  EXPECT_EQ(j["metrics"]["scaled_jacobian"]["inverted"], 0);
}

TEST(Cli, BallReportFiguresAndCsv) {
  const auto dir = scratch_dir();
  std::string out;
  ASSERT_EQ(run_cli("generate ball -n 6 -o " + q(dir / "ball.vtk"), &out), 0) << out;
  ASSERT_EQ(run_cli("quality " + q(dir / "ball.vtk") + " --metric scaled_jacobian --metric edge_ratio --histogram " +
                        q(dir / "h.svg") + " --per-element " + q(dir / "v.csv") + " --json " + q(dir / "q.json"),
                    &out),
            0)
      << out;
  EXPECT_NE(io::read_file(dir / "h-scaled_jacobian.svg").find("<svg"), std::string::npos);
  EXPECT_NE(io::read_file(dir / "h-edge_ratio.svg").find("<svg"), std::string::npos);
  std::istringstream csv(io::read_file(dir / "v.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "id,scaled_jacobian,edge_ratio");
  int rows = 0;
  double min_sj = 2;
  while (std::getline(csv, line)) {
    ++rows;
    min_sj = std::min(min_sj, std::stod(line.substr(line.find(',') + 1)));
  }
  EXPECT_EQ(rows, 216);
  const auto j = nlohmann::json::parse(io::read_file(dir / "q.json"));
  EXPECT_EQ(j["metrics"]["scaled_jacobian"]["min"].get<double>(), min_sj);
  EXPECT_LT(min_sj, 0.9);  // the mapped ball has flattened elements on the cube's diagonals
}

TEST(Cli, ThreadCountDoesNotChangeResults) {
  const auto dir = scratch_dir();
  ASSERT_EQ(run_cli("generate ball -n 20 --jitter 0.3 -o " + q(dir / "b.vtu")), 0);
  for (int t : {1, 2})
    ASSERT_EQ(run_cli("quality " + q(dir / "b.vtu") + " --metric all --threads " + std::to_string(t) +
                      " --per-element " + q(dir / ("t" + std::to_string(t) + ".csv"))),
              0);
  EXPECT_EQ(io::read_file(dir / "t1.csv"), io::read_file(dir / "t2.csv"));
}

TEST(Cli, InvalidMeshFailsCheck) {
  const auto dir = scratch_dir();
  HexMesh m = test::grid_mesh(2, 1, 1);
  std::swap(m.hexes[1][1], m.hexes[1][3]);  // mirrored node order (both quads reversed)
  std::swap(m.hexes[1][5], m.hexes[1][7]);
  io::write_mesh(dir / "bad.mesh", m);
  std::string out;
  EXPECT_EQ(run_cli("check " + q(dir / "bad.mesh") + " --json " + q(dir / "c.json"), &out), 1) << out;
  EXPECT_NE(out.find("INVALID"), std::string::npos);
  const auto j = nlohmann::json::parse(io::read_file(dir / "c.json"));
  EXPECT_EQ(j["valid"], false);
  EXPECT_GE(j["fault_counts"]["inconsistent_orientation"].get<int>(), 1);
}

TEST(Cli, BadInputGivesClearErrorsAndNoOutput) {
  const auto dir = scratch_dir();
  std::string out;
  EXPECT_EQ(run_cli("quality " + q(dir / "missing.vtu"), &out), 2);
  EXPECT_NE(out.find("missing.vtu"), std::string::npos) << out;
  EXPECT_EQ(run_cli("quality " + q(dir / "x.stl"), &out), 2);
  EXPECT_NE(out.find("unknown mesh format"), std::string::npos) << out;
  ASSERT_EQ(run_cli("generate box -n 2 -o " + q(dir / "b.vtu")), 0);
  EXPECT_EQ(run_cli("quality " + q(dir / "b.vtu") + " --metric nonsense", &out), 2);
  EXPECT_NE(out.find("unknown metric 'nonsense'"), std::string::npos) << out;
  EXPECT_NE(run_cli("quality " + q(dir / "b.vtu") + " --json " + q(dir / "no/such/dir/q.json"), &out), 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "no"));
}

TEST(Cli, ConvertRoundTripsThroughEveryFormat) {
  const auto dir = scratch_dir();
  ASSERT_EQ(run_cli("generate ball -n 3 --jitter 0.2 -o " + q(dir / "a.vtu")), 0);
  const HexMesh a = io::read_mesh(dir / "a.vtu");
  std::string prev = "a.vtu";
  for (const char* next : {"b.vtk", "c.mesh", "d.inp", "e.vtu"}) {
    std::string out;
    ASSERT_EQ(run_cli("convert " + q(dir / prev) + " " + q(dir / next), &out), 0) << out;
    prev = next;
  }
  ASSERT_EQ(run_cli("convert --ascii " + q(dir / prev) + " " + q(dir / "f.vtk")), 0);
  const HexMesh f = io::read_mesh(dir / "f.vtk");
  ASSERT_EQ(f.points.size(), a.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i) EXPECT_EQ(f.points[i], a.points[i]);
  EXPECT_EQ(f.hexes, a.hexes);
}
