// Untangling: synthetic tangled grids, impossible cases, Mesquite's tangled meshes, the CLI.
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/generate.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>

using namespace isohex;
using isohex::test::quote;
using isohex::test::run_cli;
using isohex::test::scratch_dir;
using isohex::test::shared_data;

namespace {

std::size_t inverted(const HexMesh& m) {
  std::size_t n = 0;
  for (double v : scaled_jacobians(m)) n += v <= 0 || is_degenerate(v);
  return n;
}

HexMesh tangled_box(int n, double amplitude, unsigned seed) {
  HexMesh m = box_mesh(n, n, n);
  m.fixed = boundary_vertex_mask(m);
  jitter(m, amplitude / n, seed);
  return m;
}

// Untangle + shape + worst pass with the mesh's own fixed flags; checks the guarantees.
void untangle_and_check(HexMesh& m, double want_min) {
  const HexMesh before = m;
  const UntangleResult u = untangle(m, m.fixed);
  EXPECT_TRUE(u.impossible.empty());
  EXPECT_EQ(u.inverted, 0u);
  EXPECT_EQ(inverted(m), 0u);
  optimize_shape(m, m.fixed);
  EXPECT_EQ(inverted(m), 0u);  // the shape stage never inverts a valid hex
  const WorstResult w = improve_worst(m, m.fixed);
  EXPECT_GE(w.min_sj_after, w.min_sj_before);
  EXPECT_GE(w.min_sj_after, want_min);
  for (std::size_t i = 0; i < m.points.size(); ++i)
    if (m.fixed[i]) ASSERT_EQ(m.points[i], before.points[i]) << i;
}

}  // namespace

TEST(OptimizeUntangle, TangledGridWithFixedBoundary) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    HexMesh m = tangled_box(6, 0.9, seed);
    ASSERT_GT(inverted(m), 10u) << "seed " << seed << ": the test wants a tangled start";
    untangle_and_check(m, 0.3);
  }
}

TEST(OptimizeUntangle, ReachesTheMargin) {
  HexMesh m = tangled_box(5, 0.9, 4);
  UntangleOptions o;
  o.margin = 0.2;
  const UntangleResult u = untangle(m, m.fixed, o);
  EXPECT_TRUE(u.reached_margin);
  EXPECT_GE(u.min_sj, 0.2);
}

TEST(OptimizeUntangle, ReportsHexesThatCannotBeRepaired) {
  HexMesh m = box_mesh(2, 1, 1);
  m.points[m.hexes[0][0]] = Vec3(0.45, 0.9, 0.9);  // corner 0 of hex 0 pushed through; every vertex is on the boundary
  const HexMesh before = m;
  const UntangleResult u = untangle(m, fixed_mask(m, FixedVertices::boundary));
  ASSERT_GT(inverted(m), 0u);
  ASSERT_EQ(u.impossible.size(), 1u);
  EXPECT_EQ(u.impossible[0], 0);
  EXPECT_EQ(m.points, before.points);
  // With nothing fixed the same hex can be repaired.
  const UntangleResult free = untangle(m, fixed_mask(m, FixedVertices::none));
  EXPECT_TRUE(free.impossible.empty());
  EXPECT_EQ(inverted(m), 0u);
}

TEST(OptimizeUntangle, MesquiteHex5Tangled) {
  ISOHEX_REQUIRE_SHARED_DATA();
  HexMesh m = io::read_mesh(shared_data("hexmeshes/mesquite/hex_5_tangled.vtk"));
  ASSERT_TRUE(m.has_fixed());
  ASSERT_GT(inverted(m), 0u);
  untangle_and_check(m, 0.05);
}

TEST(OptimizeUntangle, MesquitePave2) {
  ISOHEX_REQUIRE_SHARED_DATA();
  HexMesh m = io::read_mesh(shared_data("hexmeshes/mesquite/pave2.e.vtk"));
  ASSERT_TRUE(m.has_fixed());
  ASSERT_GT(inverted(m), 0u);
  untangle_and_check(m, 0.05);
}

TEST(OptimizeUntangle, CliSmoothUntanglesAndKeepsTheBoundary) {
  const auto dir = scratch_dir();
  HexMesh m = tangled_box(5, 0.9, 2);
  m.fixed.clear();  // --fixed boundary must find the boundary itself
  ASSERT_GT(inverted(m), 0u);
  io::write_mesh(dir / "in.vtk", m);
  std::string out;
  const int rc = run_cli("smooth " + quote(dir / "in.vtk") + " -o " + quote(dir / "out.vtk") + " --untangle --threads 2 --json " +
                             quote(dir / "r.json"),
                         &out);
  ASSERT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("after"), std::string::npos) << out;
  const HexMesh r = io::read_mesh(dir / "out.vtk");
  EXPECT_EQ(inverted(r), 0u);
  const auto boundary = boundary_vertex_mask(m);
  for (std::size_t i = 0; i < m.points.size(); ++i)
    if (boundary[i]) ASSERT_EQ(r.points[i], m.points[i]) << i;
  EXPECT_TRUE(std::filesystem::exists(dir / "r.json"));
  // Without --untangle the inverted hexes are held and reported, and the run still succeeds.
  ASSERT_EQ(run_cli("smooth " + quote(dir / "in.vtk") + " -o " + quote(dir / "held.vtk") + " --fixed none --max-iter 3", &out), 0)
      << out;
  EXPECT_NE(out.find("--untangle"), std::string::npos) << out;
}
