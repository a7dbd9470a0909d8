// find_quality_bounds(): upper bounds of the scaled Jacobian that fixed vertices impose,
// checked against Verdict's scaled Jacobian at random placements of the free vertices.
#include "isohex/io/mesh_io.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>

using namespace isohex;
using isohex::test::shared_data;

namespace {

// Wherever the free vertices of the proof's hexes go (random places within `reach` of where
// they are, and along the edge direction the bound says is best), the smallest Verdict scaled
// Jacobian of its hexes is at most its bound.
void check_bound(const HexMesh& m, const std::vector<std::uint8_t>& fixed, const QualityBound& b, double reach,
                 unsigned seed) {
  std::vector<Index> free;
  for (Index h : b.hexes)
    for (Index v : m.hexes[h])
      if (!fixed[v]) free.push_back(v);
  std::sort(free.begin(), free.end());
  free.erase(std::unique(free.begin(), free.end()), free.end());
  HexMesh probe = m;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-reach, reach);
  for (int i = 0; i < 2000; ++i) {
    for (Index v : free) probe.points[v] = m.points[v] + (i % 2 ? 1.0 : 0.1) * Vec3(U(rng), U(rng), U(rng));
    double lo = 2;
    for (Index h : b.hexes) lo = std::min(lo, scaled_jacobian(probe.corners(h)));
    ASSERT_LE(lo, b.bound + 1e-12) << "vertex " << b.vertex << " sample " << i;
  }
}

// One hex on a fixed parallelogram with an angle of `deg` at corner 0, its top free, at height h.
HexMesh prism(double deg, double h) {
  const double c = std::cos(deg * M_PI / 180), s = std::sin(deg * M_PI / 180);
  HexMesh m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {1 + c, s, 0}, {c, s, 0}};
  for (int k = 0; k < 4; ++k) m.points.push_back(m.points[static_cast<std::size_t>(k)] + Vec3(0, 0, h));
  m.hexes = {{0, 1, 2, 3, 4, 5, 6, 7}};
  return m;
}

}  // namespace

TEST(QualityBound, SharpQuadCornersAreBoundedByTheSineOfTheirAngle) {
  const HexMesh m = prism(10, 1);
  const std::vector<std::uint8_t> fixed{1, 1, 1, 1, 0, 0, 0, 0};
  const std::vector<QualityBound> bounds = find_quality_bounds(m, fixed, 0.2);
  // Each bottom corner frame has two fixed edges at 10 or 170 degrees and one free edge up.
  ASSERT_EQ(bounds.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(bounds[k].kind, QualityBound::Kind::edge_direction);
    EXPECT_EQ(bounds[k].vertex, static_cast<Index>(k));
    EXPECT_EQ(bounds[k].free, static_cast<Index>(k + 4));
    EXPECT_NEAR(bounds[k].bound, std::sin(10 * M_PI / 180), 1e-12);
    EXPECT_EQ(bounds[k].hexes, (std::vector<Index>{0}));
    check_bound(m, fixed, bounds[k], 1.0, static_cast<unsigned>(k));
  }
  // The bound is reached: the top straight above the bottom gives Verdict's value sin 10°.
  EXPECT_NEAR(scaled_jacobian(m.corners(0)), std::sin(10 * M_PI / 180), 1e-12);
  // At 20 degrees the corners can reach 0.342 > 0.2: nothing to prove.
  EXPECT_TRUE(find_quality_bounds(prism(20, 1), fixed, 0.2).empty());
  // Nothing fixed, nothing proven; all fixed: the hex's frames themselves.
  EXPECT_TRUE(find_quality_bounds(m, {}, 0.2).empty());
  const auto all = find_quality_bounds(m, std::vector<std::uint8_t>(8, 1), 0.2);
  ASSERT_FALSE(all.empty());
  for (const QualityBound& b : all) {
    EXPECT_EQ(b.kind, QualityBound::Kind::fixed_frame);
    EXPECT_NEAR(b.bound, std::sin(10 * M_PI / 180), 1e-12);
  }
}

TEST(QualityBound, EcrBlockKeepsOnlyProvenHexesBelowTheFloor) {
  ISOHEX_REQUIRE_SHARED_DATA();
  HexMesh m = io::read_mesh(shared_data("hexmeshes/ecr2015_block_in.mesh"));
  const auto fixed = fixed_mask(m, FixedVertices::boundary);
  const std::vector<QualityBound> bounds = find_quality_bounds(m, fixed, 0.2);
  // A boundary vertex of valence 3 whose three quads' corners (one at 168 degrees) share one
  // free edge: the best direction of that edge gives the three frames 0.197 at most.
  ASSERT_EQ(bounds.size(), 1u);
  EXPECT_EQ(bounds[0].kind, QualityBound::Kind::edge_direction);
  EXPECT_EQ(bounds[0].hexes.size(), 3u);
  EXPECT_NEAR(bounds[0].bound, 0.1972, 1e-4);
  double len = 0;
  for (Index h : bounds[0].hexes) len = std::max(len, (m.points[m.hexes[h][0]] - m.points[m.hexes[h][6]]).norm());
  check_bound(m, fixed, bounds[0], len, 3);
  // `isohex smooth --untangle` with the boundary fixed: every hex left below 0.2 is in a proof,
  // and comes within 0.001 of its bound.
  OptimizeOptions o;
  const OptimizeResult r = optimize_mesh(m, fixed, o);
  ASSERT_EQ(r.worst.proven.size(), 1u);
  const std::set<Index> proven(bounds[0].hexes.begin(), bounds[0].hexes.end());
  std::size_t below = 0;
  for (Index h = 0; h < m.num_hexes(); ++h) {
    const double q = scaled_jacobian(m.corners(h));
    if (q >= 0.2) continue;
    ++below;
    EXPECT_TRUE(proven.count(h)) << "hex " << h << " at " << q << " has no proof";
    EXPECT_GT(q, bounds[0].bound - 1e-3);
  }
  EXPECT_EQ(below, 1u);
}

// `isohex smooth` reports the proofs (JSON worst.proven and on stdout), and --worst-passes out of
// range exits 2 before anything is written.
TEST(QualityBound, CliSmoothReportsTheProofs) {
  ISOHEX_REQUIRE_SHARED_DATA();
  using test::quote;
  const auto dir = test::scratch_dir();
  const std::string in = quote(shared_data("hexmeshes/ecr2015_block_in.mesh"));
  std::string out;
  ASSERT_EQ(test::run_cli("smooth " + in + " -o " + quote(dir / "out.vtu") + " --untangle --worst-passes 40 --json " +
                              quote(dir / "r.json"),
                          &out),
            0)
      << out;
  EXPECT_NE(out.find("proven with the fixed vertices"), std::string::npos) << out;
  std::ifstream f(dir / "r.json");
  const auto j = nlohmann::json::parse(f);
  ASSERT_EQ(j["worst"]["proven"].size(), 1u);
  EXPECT_EQ(j["worst"]["proven"][0]["kind"], "edge_direction");
  EXPECT_NEAR(j["worst"]["proven"][0]["bound"].get<double>(), 0.1972, 1e-4);
  EXPECT_EQ(j["worst"]["proven"][0]["hexes"].size(), 3u);
  EXPECT_LE(j["after"]["below_0.2"].get<int>(), 1);
  EXPECT_EQ(test::run_cli("smooth " + in + " -o " + quote(dir / "bad.vtu") + " --worst-passes 0", &out), 2) << out;
  EXPECT_NE(out.find("--worst-passes"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.vtu"));
}
