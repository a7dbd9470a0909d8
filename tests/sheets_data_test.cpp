// Boundary pillowing and the shrink-set specifications on the shared ECR 2015 meshes and via the CLI.
#include "isohex/contour/dual_contour.hpp"
#include "isohex/contour/region.hpp"
#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/validate.hpp"
#include "isohex/sheets/dual_sheets.hpp"
#include "isohex/sheets/pillow.hpp"
#include "isohex/volume/implicit.hpp"
#include "sheets_support.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

namespace isohex::test {
namespace {

constexpr auto q = quote;

TEST(PillowData, EcrMeshesGetOneBoundarySheetPerComponentAndKeepTheirSurface) {
  ISOHEX_REQUIRE_SHARED_DATA();
  for (const char* name : {"block", "bust", "hanger_stresstest", "impeller_stresstest", "dragon", "armadillo"}) {
    SCOPED_TRACE(name);
    const HexMesh m = io::read_mesh(shared_data(std::string("hexmeshes/ecr2015_") + name + "_out.mesh"));
    const PillowResult r = checked_pillow(m, std::vector<std::uint8_t>(m.hexes.size(), 1), {.include_boundary = true});
    EXPECT_TRUE(same_surface(m, r.mesh));
    EXPECT_EQ(r.interface_quads, validate(m).num_boundary_quads);
    const SheetReport s = extract_sheets(r.mesh);
    for (const auto& sheets : s.boundary_capture) EXPECT_EQ(sheets.size(), 1u);
    EXPECT_EQ(s.multi_boundary_hexes, 0u);
  }
}

TEST(PillowData, ShrinkSetSpecifications) {
  HexMesh m = grid_mesh(4, 4, 4);
  m.blocks.assign(m.hexes.size(), 1);
  m.blocks[5] = 2;
  const auto all = shrink_set_from_spec(m, "boundary");
  EXPECT_EQ(std::count(all.begin(), all.end(), 1), 64);
  const auto b = shrink_set_from_spec(m, "block:2");
  EXPECT_EQ(std::count(b.begin(), b.end(), 1), 1);
  EXPECT_EQ(b[5], 1);
  const auto region = shrink_set_from_spec(m, "region:box(0,0,0, 2,2,2)");
  EXPECT_EQ(std::count(region.begin(), region.end(), 1), 8);  // centroids at 0.5 and 1.5
  const auto dir = scratch_dir();
  {
    std::ofstream f(dir / "ids.txt");
    f << "# two hexes\n3\n\n 17 \n";
  }
  const auto ids = shrink_set_from_spec(m, "ids:" + (dir / "ids.txt").string());
  EXPECT_EQ(std::count(ids.begin(), ids.end(), 1), 2);
  EXPECT_EQ(ids[3] + ids[17], 2);
  {
    std::ofstream f(dir / "bad.txt");
    f << "3\n4x\n";
  }
  auto message = [&](const std::string& spec) {
    try {
      shrink_set_from_spec(m, spec);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("ids:" + (dir / "bad.txt").string()).find("line 2: '4x' is not a hex id"), std::string::npos);
  {
    std::ofstream f(dir / "range.txt");
    f << "64\n";
  }
  EXPECT_NE(message("ids:" + (dir / "range.txt").string()).find("line 1: hex id 64 is out of range [0, 64)"),
            std::string::npos);
  EXPECT_NE(message("ids:" + (dir / "missing.txt").string()).find("cannot open"), std::string::npos);
  EXPECT_NE(message("sphere:1").find("unknown specification"), std::string::npos);
  EXPECT_NE(message("region:sphere(0,0").find("column"), std::string::npos);
  EXPECT_NE(message("block:x").find("not a block id"), std::string::npos);
  EXPECT_TRUE(spec_includes_boundary("boundary"));
  EXPECT_TRUE(spec_includes_boundary("block:3"));
  EXPECT_FALSE(spec_includes_boundary("region:sphere(0,0,0,1)"));
}

TEST(PillowCli, PillowThenSheets) {
  const auto dir = scratch_dir();
  std::string out;
  ASSERT_EQ(run_cli("generate box -n 3 --size 3 -o " + q(dir / "box.vtu"), &out), 0) << out;
  ASSERT_EQ(run_cli("pillow " + q(dir / "box.vtu") + " -o " + q(dir / "p.vtu") + " --json " + q(dir / "p.json"), &out), 0)
      << out;
  EXPECT_NE(out.find("hexes with >= 2 boundary faces: 20 before, 0 after"), std::string::npos) << out;
  const auto j = nlohmann::json::parse(io::read_file(dir / "p.json"));
  EXPECT_EQ(j["interface_quads"], 54);
  EXPECT_EQ(j["hexes_after"], 27 + 54);
  EXPECT_GT(j["min_new_scaled_jacobian"].get<double>(), 0);
  ASSERT_EQ(run_cli("sheets " + q(dir / "p.vtu") + " --json " + q(dir / "s.json"), &out), 0) << out;
  const auto s = nlohmann::json::parse(io::read_file(dir / "s.json"));
  EXPECT_EQ(s["sheets"], 10);
  EXPECT_EQ(s["components_captured_by_one_sheet"], 1);
  EXPECT_EQ(s["multi_boundary_hexes"], 0);

  ASSERT_EQ(run_cli("pillow " + q(dir / "box.vtu") + " -o " + q(dir / "r.vtu") + " --shrink-set 'region:sphere(1.5,1.5,1.5,0.6)'",
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("interface: 6 quads, 8 vertices"), std::string::npos) << out;
  EXPECT_EQ(run_cli("pillow " + q(dir / "box.vtu") + " -o " + q(dir / "e.vtu") + " --shrink-set 'region:sphere(9,9,9,0.1)'",
                    &out),
            2);
  EXPECT_NE(out.find("shrink set is empty"), std::string::npos) << out;

  {  // two hexes of the 3³ box touching along an edge: two extra copies
    std::ofstream f(dir / "ids.txt");
    f << "0\n4\n";
  }
  ASSERT_EQ(run_cli("pillow " + q(dir / "box.vtu") + " -o " + q(dir / "i.vtu") + " --shrink-set ids:" +
                        (dir / "ids.txt").string(),
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("pinch copies: 2"), std::string::npos) << out;
  {
    std::ofstream f(dir / "bad.txt");
    f << "0\nfour\n";
  }
  EXPECT_EQ(run_cli("pillow " + q(dir / "box.vtu") + " -o " + q(dir / "b.vtu") + " --shrink-set ids:" +
                        (dir / "bad.txt").string(),
                    &out),
            2);
  EXPECT_NE(out.find("line 2: 'four' is not a hex id"), std::string::npos) << out;

  {  // all but two hexes of a 2³ box touching at the centre: an outer pinch, pillowed
    std::ofstream f(dir / "outer.txt");
    f << "1\n2\n3\n4\n5\n6\n";
  }
  ASSERT_EQ(run_cli("generate box -n 2 --size 2 -o " + q(dir / "box2.vtu"), &out), 0) << out;
  ASSERT_EQ(run_cli("pillow " + q(dir / "box2.vtu") + " -o " + q(dir / "o.vtu") + " --shrink-set ids:" +
                        (dir / "outer.txt").string() + " --json " + q(dir / "o.json"),
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("pinch copies: 1 (2 taken by outside hexes)"), std::string::npos) << out;
  const auto o = nlohmann::json::parse(io::read_file(dir / "o.json"));
  EXPECT_EQ(o["hexes_after"], 8 + 6);
  EXPECT_EQ(o["vertices_after"], 27 + 13 + 1);
  EXPECT_EQ(o["inverted_new_hexes"], 0);
  EXPECT_TRUE(validate(io::read_mesh(dir / "o.vtu")).valid());
}

/// The extraction's output (raw dual contouring, in process so that the test does not depend
/// on the stages `isohex mesh` runs), pillowed via the CLI: one new sheet captures each
/// boundary component (a ball with a cavity and a torus: three components) and no hex keeps
/// two boundary faces.
TEST(PillowCli, ExtractedShapeGetsOneSheetPerBoundaryComponent) {
  const auto dir = scratch_dir();
  const Shape shape =
      parse_shape("difference(union(sphere(0,0,0,1), torus(3,0,0,1,0.4)), sphere(0,0,0,0.5))");
  const double h = 0.18;
  const Volume volume = sample(shape, grid_from_cell_size(sampling_bounds(shape), h));
  contour::RegionSpec spec;
  spec.isovalue = 0;
  spec.inside = Inside::below;
  contour::ExtractOptions opt;
  opt.cell_size = h;
  const HexMesh a = contour::extract_hex_mesh(contour::make_region(volume, spec), opt).mesh;
  io::write_mesh(dir / "a.vtu", a);
  const ValidationReport va = validate(a);
  ASSERT_TRUE(va.valid());
  ASSERT_EQ(va.num_boundary_components, 3u);

  std::string out;
  ASSERT_EQ(run_cli("pillow " + q(dir / "a.vtu") + " -o " + q(dir / "b.vtu") + " --json " + q(dir / "b.json"), &out), 0)
      << out;
  ASSERT_EQ(run_cli("sheets " + q(dir / "a.vtu") + " --json " + q(dir / "sa.json"), &out), 0) << out;
  ASSERT_EQ(run_cli("sheets " + q(dir / "b.vtu") + " --json " + q(dir / "sb.json"), &out), 0) << out;
  const auto b = nlohmann::json::parse(io::read_file(dir / "b.json"));
  const auto sa = nlohmann::json::parse(io::read_file(dir / "sa.json"));
  const auto sb = nlohmann::json::parse(io::read_file(dir / "sb.json"));
  EXPECT_EQ(b["interface_quads"], va.num_boundary_quads);
  EXPECT_EQ(b["hexes_after"], a.hexes.size() + va.num_boundary_quads);
  EXPECT_GT(sa["multi_boundary_hexes"].get<int>(), 0);
  EXPECT_EQ(sa["components_captured_by_one_sheet"], 0);
  EXPECT_EQ(sb["components_captured_by_one_sheet"], 3);
  EXPECT_EQ(sb["multi_boundary_hexes"], 0);
  const HexMesh m = io::read_mesh(dir / "b.vtu");
  const ValidationReport v = validate(m);
  EXPECT_TRUE(v.valid());
  EXPECT_EQ(v.num_boundary_components, 3u);
  EXPECT_EQ(v.euler_characteristic, va.euler_characteristic);
  EXPECT_TRUE(same_surface(a, m));
}

}  // namespace
}  // namespace isohex::test
