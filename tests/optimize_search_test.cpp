// The worst pass's last resort: a random walk across the level set of the minimum
// (optimize/search.hpp).
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/search.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

using namespace isohex;

namespace {

double lowest_rank(const HexMesh& m) {
  double lo = 2;
  for (Index h = 0; h < m.num_hexes(); ++h) lo = std::min(lo, opt::hex_rank(certified_quality(m.corners(h))));
  return lo;
}

// Every hex of `after` keeps what the search promises against `before`: certified valid, its
// scaled Jacobian not below the lower of its value and 0.2, its ratio bound not below the lower
// of its value and 0.2, its edge ratio not above the higher of its value and 20, its rank not
// below the lowest rank of `before`; held vertices stay.
// (`walk_only` false: after the whole worst pass, whose single moves hold the ratio and edge
// floors over the hexes around a vertex, not per hex; those two are then not checked.)
void expect_guards(const HexMesh& before, const HexMesh& after, const std::string& what, bool walk_only = true) {
  const double lo = lowest_rank(before);
  for (Index h = 0; h < before.num_hexes(); ++h) {
    const CertifiedQuality b = certified_quality(before.corners(h)), a = certified_quality(after.corners(h));
    EXPECT_TRUE(certified_valid(after.corners(h), 0.0)) << what << " hex " << h;
    EXPECT_GE(a.scaled_jacobian, std::min(b.scaled_jacobian, 0.2) - 1e-12) << what << " hex " << h;
    if (!walk_only) continue;
    EXPECT_GE(a.ratio_bound, std::min(b.ratio_bound, 0.2) - 1e-12) << what << " hex " << h;
    EXPECT_LE(edge_ratio(after.corners(h)), std::max(edge_ratio(before.corners(h)), 20.0) + 1e-9) << what << " hex " << h;
    EXPECT_GE(opt::hex_rank(a), lo - 1e-12) << what << " hex " << h;
  }
  for (Index v = 0; v < before.num_vertices(); ++v)
    if (before.fixed[v]) EXPECT_EQ(after.points[v], before.points[v]) << what << " vertex " << v;
}

}  // namespace

// tests/data/bone_stall.txt: where cthead's bone at iso 1200, h 5 ended (7f3d5ce) with four
// pillow hexes at a ratio of 0.052, the single and joint max–min moves stalled with its boundary
// vertices loose in their band. Here they are free in space, and the single moves run until
// they stop; the walk from there lifts the whole piece to a rank of 0.2 (every hex at a scaled
// Jacobian of 0.2 and a ratio of 0.1), keeping every guard, and gives the same mesh when run
// again. (The joint moves are left out: their LPs take a minute here.)
TEST(OptimizeSearch, WalksOnWhereTheMaxMinMovesStall) {
  std::vector<Index> targets;
  const HexMesh piece = test::read_piece("bone_stall.txt", targets, true);
  ASSERT_EQ(piece.num_hexes(), 260);
  ASSERT_EQ(targets.size(), 4u);
  const double start = lowest_rank(piece);
  ASSERT_LT(start, 0.11);

  HexMesh stalled = piece;
  const WorstResult s = test::stall_single_moves(stalled, 1000);
  ASSERT_LT(s.passes, 1000);  // it stopped: no single move gains
  EXPECT_EQ(s.searched, 0u);
  const double stalled_rank = lowest_rank(stalled);
  EXPECT_LT(stalled_rank, 0.19);

  WorstOptions walk;  // the single moves and the walk, as above without the joint moves
  walk.patch_rounds = 0;
  walk.passes = 1000;
  HexMesh walked = stalled;
  const WorstResult w = improve_worst(walked, walked.fixed, walk);
  EXPECT_GE(w.searched, 1u);
  EXPECT_GE(w.search_gains, 1u);
  const double walked_rank = lowest_rank(walked);
  EXPECT_GE(walked_rank, 0.2);
  expect_guards(stalled, walked, "walk", false);

  HexMesh again = stalled;
  improve_worst(again, again.fixed, walk);
  EXPECT_EQ(again.points, walked.points);  // sequential, a fixed seed
  std::printf("start %.4f, max-min moves %.4f, walk %.4f\n", start, stalled_rank, walked_rank);
}

// search_region() on its own, property test: on the piece with small deterministic jitters and
// with budgets from a few steps to many, with the boundary held or free, it never breaks a
// guard, never lowers the piece's minimum, and leaves the mesh unchanged when it reports no gain.
TEST(OptimizeSearch, KeepsItsGuards) {
  std::size_t gained = 0, runs = 0;
  for (bool free_boundary : {false, true}) {
    std::vector<Index> targets;
    const HexMesh base = test::read_piece("bone_stall.txt", targets, free_boundary);
    std::sort(targets.begin(), targets.end());
    for (unsigned seed = 1; seed <= 4; ++seed) {
      HexMesh m = base;
      for (Index v = 0; v < m.num_vertices(); ++v) {
        if (m.fixed[v]) continue;
        const Vec3 old = m.points[v];
        m.points[v] += 0.05 * Vec3(std::sin(seed * 12.9898 + v * 78.233), std::sin(seed * 4.1414 + v * 3.7),
                                   std::sin(seed * 9.17 + v * 1.31));
        bool ok = true;
        for (Index h = 0; h < m.num_hexes(); ++h) ok = ok && certified_valid(m.corners(h), 0.0);
        if (!ok) m.points[v] = old;
      }
      const Incidence inc = vertex_hexes(m);
      WorstOptions o;
      o.search_trials = seed == 1 ? 50 : 5000 * seed;
      const HexMesh before = m;
      double mesh_min = 2;
      for (Index h = 0; h < m.num_hexes(); ++h) mesh_min = std::min(mesh_min, certified_scaled_jacobian(m.corners(h)));
      const opt::SearchOutcome r = opt::search_region(m, inc, m.fixed, targets, before.points, o, mesh_min);
      ++runs;
      EXPECT_GE(r.after, r.before);
      EXPECT_LE(r.trials, o.search_trials);
      expect_guards(before, m, "seed " + std::to_string(seed));
      for (Index h = 0; h < m.num_hexes(); ++h)
        for (const auto& e : kHexEdges) {
          const Index a = m.hexes[h][e[0]], b = m.hexes[h][e[1]];
          EXPECT_GE((m.points[a] - m.points[b]).norm(), o.min_edge_shrink * (before.points[a] - before.points[b]).norm() - 1e-12);
        }
      if (r.after > r.before) {
        ++gained;
        EXPECT_GE(lowest_rank(m), r.after - 1e-12);
      } else {
        EXPECT_EQ(m.points, before.points);
      }
    }
  }
  EXPECT_GT(gained, 0u);
  EXPECT_EQ(runs, 8u);
}

// Hexes held (improve_worst() holds the members of find_quality_bounds()' sets, which its fixed
// vertices keep below 0.2): on the stalled piece, the walk's minimum is its lowest hex's rank;
// with that hex held, the minimum of the others, which the walk lifts to 0.2 while the held hex
// never falls below its own rank (it is the lowest: the lower of that and the others' minimum).
TEST(OptimizeSearch, HeldHexesDoNotCountInTheMinimum) {
  std::vector<Index> targets;
  HexMesh stalled = test::read_piece("bone_stall.txt", targets, true);
  test::stall_single_moves(stalled, 1000);
  const auto rank_of = [](const HexMesh& m, Index h) { return opt::hex_rank(certified_quality(m.corners(h))); };
  const Index h0 = *std::min_element(targets.begin(), targets.end(),
                                     [&](Index a, Index b) { return rank_of(stalled, a) < rank_of(stalled, b); });
  std::vector<std::uint8_t> held(stalled.hexes.size(), 0);
  held[h0] = 1;
  const auto others_min = [&](const HexMesh& m) {
    double lo = 2;
    for (Index h = 0; h < m.num_hexes(); ++h)
      if (h != h0) lo = std::min(lo, rank_of(m, h));
    return lo;
  };
  ASSERT_LT(rank_of(stalled, h0), others_min(stalled) - 0.005);
  double mesh_min = 2;
  for (Index h = 0; h < stalled.num_hexes(); ++h) mesh_min = std::min(mesh_min, certified_scaled_jacobian(stalled.corners(h)));
  const Incidence inc = vertex_hexes(stalled);
  WorstOptions o;
  o.search_trials = 40000;

  HexMesh counted = stalled;
  const opt::SearchOutcome c = opt::search_region(counted, inc, counted.fixed, targets, stalled.points, o, mesh_min);
  EXPECT_EQ(c.before, rank_of(stalled, h0));
  HexMesh walked = stalled;
  const opt::SearchOutcome w = opt::search_region(walked, inc, walked.fixed, targets, stalled.points, o, mesh_min, held);
  EXPECT_EQ(w.before, others_min(stalled));
  EXPECT_GE(w.after, 0.2);
  EXPECT_GE(others_min(walked), w.after - 1e-12);
  EXPECT_GE(rank_of(walked, h0), rank_of(stalled, h0) - 1e-12);
  expect_guards(stalled, walked, "held");
  std::printf("held hex %.4f -> %.4f; the others %.4f -> %.4f\n", rank_of(stalled, h0), rank_of(walked, h0),
              others_min(stalled), others_min(walked));
}

// `isohex smooth --search-trials`: the walk is counted in the JSON report (the piece held at
// its outer layer, as `--fixed file` reads it), 0 turns it off, and a negative value exits 2
// before anything is written.
TEST(OptimizeSearch, CliSmoothSearchTrials) {
  EXPECT_GT(test::smooth_piece_count("bone_stall.txt", " --patch-rounds 0", "search_gains"), 0u);
  EXPECT_EQ(test::smooth_piece_count("bone_stall.txt", " --patch-rounds 0 --search-trials 0", "search_gains"), 0u);
  test::expect_smooth_refuses("bone_stall.txt", "--search-trials", "-5");
}
