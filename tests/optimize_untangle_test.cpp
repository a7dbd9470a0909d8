// Untangling: synthetic tangled grids, impossible cases, Mesquite's tangled meshes, the CLI.
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/generate.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/feasibility.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <fstream>
#include <random>

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
  EXPECT_TRUE(u.infeasible.empty());
  EXPECT_TRUE(u.given_up.empty());
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
  ASSERT_EQ(u.infeasible.size(), 1u);
  EXPECT_EQ(u.infeasible[0].kind, InfeasibleSet::Kind::fixed_frame);
  EXPECT_EQ(u.infeasible[0].hexes, std::vector<Index>{0});
  EXPECT_EQ(u.given_up, std::vector<Index>{0});
  EXPECT_EQ(m.points, before.points);
  // With nothing fixed the same hex can be repaired.
  const UntangleResult free = untangle(m, fixed_mask(m, FixedVertices::none));
  EXPECT_TRUE(free.infeasible.empty());
  EXPECT_EQ(inverted(m), 0u);
}

namespace {

// A 4×4×2 box whose top face is folded at its centre vertex u: the fixed edges around u turn
// back on themselves, so no place of the free vertex below u keeps all four corners at u
// positive. A tangle elsewhere (jitter of the free vertices) must still be untangled.
HexMesh folded_box() {
  HexMesh m = box_mesh(4, 4, 2, Vec3::Zero(), Vec3(4, 4, 2));
  const auto id = [](int i, int j, int k) { return static_cast<Index>(i + 5 * (j + 5 * k)); };
  m.points[id(2, 3, 2)] = Vec3(2.3, 1.5, 2);  // the edge u→(2,3,2) now points back past u→(2,1,2)
  const auto fixed = boundary_vertex_mask(m);
  HexMesh j = m;
  jitter(j, 0.35, 5);
  for (Index v = 0; v < m.num_vertices(); ++v)
    if (!fixed[v] && v != id(2, 2, 1)) m.points[v] = j.points[v];
  return m;
}

}  // namespace

TEST(OptimizeUntangle, ProvesAnEmptyVertexConeAndUntanglesTheRest) {
  HexMesh m = folded_box();
  const auto fixed = fixed_mask(m, FixedVertices::boundary);
  const HexMesh before = m;
  const UntangleResult u = untangle(m, fixed);
  const auto cone = std::find_if(u.infeasible.begin(), u.infeasible.end(),
                                 [](const InfeasibleSet& s) { return s.kind == InfeasibleSet::Kind::vertex_cone; });
  ASSERT_NE(cone, u.infeasible.end());
  EXPECT_EQ(cone->vertex, 2 + 5 * (2 + 5 * 1));  // the free vertex below the fold
  EXPECT_EQ(cone->hexes.size(), 8u);  // all around it: its corners at the two fixed face centres see only it free
  // The proof holds whatever the other free vertices do: wherever its vertex goes, one of its
  // hexes is invalid (checked with Verdict's scaled Jacobian, not our frames).
  HexMesh probe = before;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1.5, 1.5);
  for (int s = 0; s < 2000; ++s) {
    probe.points[cone->vertex] = before.points[cone->vertex] + Vec3(U(rng), U(rng), U(rng));
    double lo = 1;
    for (Index h : cone->hexes) {
      const double q = scaled_jacobian(probe.corners(h));
      lo = std::min(lo, is_degenerate(q) ? -1.0 : q);
    }
    ASSERT_LE(lo, 0.0) << "sample " << s;
  }
  // Only given-up hexes stay inverted, one or more per proof, and the fixed vertices keep their bits.
  ASSERT_FALSE(u.given_up.empty());
  const std::vector<double> sj = scaled_jacobians(m);
  for (Index h = 0; h < m.num_hexes(); ++h)
    if (!std::binary_search(u.given_up.begin(), u.given_up.end(), h)) EXPECT_GT(sj[h], 0.0) << h;
  for (const InfeasibleSet& s : u.infeasible) {
    std::size_t hit = 0;
    for (Index h : s.hexes) hit += std::binary_search(u.given_up.begin(), u.given_up.end(), h);
    EXPECT_GE(hit, 1u);
  }
  for (Index v = 0; v < m.num_vertices(); ++v)
    if (fixed[v]) ASSERT_EQ(m.points[v], before.points[v]) << v;
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

TEST(OptimizeUntangle, MaxMinLpMovesRaiseTheMinimumAndIgnoreThreadCount) {
  const HexMesh in = tangled_box(6, 0.9, 11);
  const auto fixed = fixed_mask(in, FixedVertices::boundary);
  const Incidence inc = vertex_hexes(in);
  const VertexColoring coloring = color_vertices(in, fixed);
  const std::vector<double> il = opt::inverse_edge_lengths(in);
  const auto min_det = [&](const HexMesh& m) {
    double lo = 1e300;
    for (Index h = 0; h < m.num_hexes(); ++h)
      for (int t = 0; t < opt::kFrames; ++t) lo = std::min(lo, opt::frame(m.corners(h), t, il[h]).determinant());
    return lo;
  };
  std::vector<std::uint8_t> active(in.points.size(), 1);
  std::vector<Vec3> out[2];
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    HexMesh m = in;
    double lo = min_det(m);
    const double start = lo;
    ASSERT_LT(lo, 0.0);
    for (int round = 0; round < 30; ++round) {
      opt::max_min_sweep(m, coloring, inc, il, active, nullptr);
      const double now = min_det(m);
      EXPECT_GE(now, lo) << "round " << round;  // each move raises its vertex's minimum: the mesh's cannot fall
      lo = now;
    }
    // Coordinate max–min ascent stalls at a kink (here at 0): it is the barrier's helper, not
    // an untangler on its own. It must still have gained.
    EXPECT_GT(lo, start + 0.05);
    for (Index v = 0; v < m.num_vertices(); ++v)
      if (fixed[v]) ASSERT_EQ(m.points[v], in.points[v]);
    out[threads - 1] = m.points;
  }
  EXPECT_EQ(out[0], out[1]);
}

TEST(OptimizeUntangle, CliWritesTheMeshListsTheProofsAndExitsOne) {
  const auto dir = scratch_dir();
  HexMesh m = folded_box();
  io::write_mesh(dir / "folded.vtk", m);
  std::string out;
  const int rc = run_cli("smooth " + quote(dir / "folded.vtk") + " -o " + quote(dir / "out.vtk") + " --untangle --json " +
                             quote(dir / "r.json"),
                         &out);
  EXPECT_EQ(rc, 1) << out;  // hexes stay inverted: scripts must notice
  EXPECT_NE(out.find("vertex_cone: free vertex 37"), std::string::npos) << out;
  ASSERT_TRUE(std::filesystem::exists(dir / "out.vtk"));  // ... but the rest is untangled and written
  std::ifstream json(dir / "r.json");
  const std::string text((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"vertex_cone\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"given_up\""), std::string::npos) << text;
  const HexMesh r = io::read_mesh(dir / "out.vtk");
  EXPECT_GE(inverted(r), 1u);
}

TEST(OptimizeUntangle, ACollapsedEdgeOfFixedVerticesIsAProof) {
  HexMesh m = box_mesh(3, 3, 3);
  // Two neighbouring boundary vertices at the same place: Verdict calls every hex on that edge
  // degenerate, wherever the free vertices go.
  const Index a = 1, b = 2;  // on the z = 0 face, along x
  m.points[a] = m.points[b];
  const auto fixed = fixed_mask(m, FixedVertices::boundary);
  const std::vector<InfeasibleSet> sets = find_infeasible(m, fixed);
  std::vector<Index> proven;
  for (const InfeasibleSet& s : sets) {
    EXPECT_EQ(s.kind, InfeasibleSet::Kind::fixed_frame);
    proven.insert(proven.end(), s.hexes.begin(), s.hexes.end());
  }
  std::vector<Index> on_edge;
  for (Index h = 0; h < m.num_hexes(); ++h) {
    const Hex& hx = m.hexes[h];
    if (std::count(hx.begin(), hx.end(), a) && std::count(hx.begin(), hx.end(), b)) on_edge.push_back(h);
  }
  EXPECT_EQ(proven, on_edge);
  for (Index h : on_edge) EXPECT_TRUE(is_degenerate(scaled_jacobian(m.corners(h))));
}

// Culling, on headsq pillowed with its skin fixed (4,002 hexes, some stuck for good): the
// vertices around the stuck hexes settle after a few of the ~50 iterations and are held after,
// so the untangler sweeps a third fewer vertices an iteration and leaves about as many
// inverted (18 / 18). It also runs longer before it stalls (60 iterations against 49: what
// it sweeps keeps gaining a little), so in all it sweeps a fifth fewer (155,077 / 190,759).
TEST(OptimizeUntangle, CullingHoldsVerticesThatSettled) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const auto dir = scratch_dir();
  std::string out;
  ASSERT_EQ(run_cli("mesh " + quote(shared_data("volumes/headsq_64x64x93_int16le.raw")) +
                        " --dims 64 64 93 --type i16 --endian little --iso 1150 --cell-size 3.2 --no-smooth -o " +
                        quote(dir / "pillowed.vtu"),
                    &out),
            0)
      << out;
  const HexMesh start = io::read_mesh(dir / "pillowed.vtu");
  const std::vector<std::uint8_t> fixed = boundary_vertex_mask(start);
  ASSERT_GT(inverted(start), 100u) << "the test wants a tangled start";
  HexMesh all = start, culled = start;
  UntangleOptions o;
  o.cull = 0;
  const UntangleResult ra = untangle(all, fixed, o);
  o.cull = 0.01;
  const UntangleResult rc = untangle(culled, fixed, o);
  ASSERT_GT(ra.iterations, 20) << "the test wants a long run";
  const auto per_iteration = [](const UntangleResult& r) { return static_cast<double>(r.vertex_sweeps) / r.iterations; };
  EXPECT_LT(per_iteration(rc), 0.7 * per_iteration(ra)) << rc.iterations << " / " << ra.iterations << " iterations";
  EXPECT_LT(rc.vertex_sweeps, ra.vertex_sweeps * 17 / 20) << ra.vertex_sweeps << " without culling";
  EXPECT_LE(inverted(culled), inverted(all) + 2) << inverted(all) << " without culling";
  for (std::size_t i = 0; i < culled.points.size(); ++i)
    if (fixed[i]) ASSERT_EQ(culled.points[i], start.points[i]) << i;
}
