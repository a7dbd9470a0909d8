// The worst pass's end game: joint max–min moves of patches of vertices (optimize/patch.hpp),
// and the LP in many unknowns that they solve.
#include "isohex/io/mesh_io.hpp"
#include "isohex/optimize/feasibility.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/patch.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

using namespace isohex;

namespace {

// tests/data/bone_cluster.txt: a piece of a real mesh, the patch's interior vertices free (and
// its boundary vertices too with `boundary_free`), and the hexes it is for.
HexMesh bone_cluster(std::vector<Index>& targets, bool boundary_free = false) {
  return test::read_piece("bone_cluster.txt", targets, boundary_free);
}

double lowest_rank(const HexMesh& m, const std::vector<Index>& hexes) {
  double lo = 2;
  for (Index h : hexes) lo = std::min(lo, opt::hex_rank(certified_quality(m.corners(h))));
  return lo;
}

double min_certified_sj(const HexMesh& m) {
  double lo = 2;
  for (Index h = 0; h < m.num_hexes(); ++h) lo = std::min(lo, certified_scaled_jacobian(m.corners(h)));
  return lo;
}

// The bone cluster with its free vertices `patch` jittered by up to 0.05 mm (deterministic in
// `seed`), each kept where it leaves every hex certified.
HexMesh jittered_bone(unsigned seed, std::vector<Index>& targets, std::vector<Index>& patch) {
  HexMesh m = bone_cluster(targets);
  patch.clear();
  for (Index v = 0; v < m.num_vertices(); ++v)
    if (!m.fixed[v]) patch.push_back(v);
  for (Index v : patch) {
    const Vec3 old = m.points[v];
    const double a = 0.05 * std::sin(seed * 12.9898 + v * 78.233), b = 0.05 * std::sin(seed * 4.1414 + v * 3.7),
                 c = 0.05 * std::sin(seed * 9.17 + v * 1.31);
    m.points[v] = old + Vec3(a, b, c);
    bool ok = true;
    for (Index h = 0; h < m.num_hexes(); ++h) ok = ok && certified_valid(m.corners(h), 0.0);
    if (!ok) m.points[v] = old;
  }
  return m;
}

}  // namespace

// max s with d_i >= s (i < n) and 1 − Σ d_i >= s: every d_i = s = 1/(n + 1).
TEST(OptimizePatch, LpInManyUnknownsFindsTheKnownOptimum) {
  for (int n = 1; n <= 12; ++n) {
    std::vector<double> a, b, w;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) a.push_back(i == j ? 1.0 : 0.0);
      b.push_back(0), w.push_back(1);
    }
    for (int j = 0; j < n; ++j) a.push_back(-1.0);
    b.push_back(1), w.push_back(1);
    const opt::MaxMinN r = opt::max_min_affine(n, a, b, w, std::vector<double>(n, 1.0));
    ASSERT_TRUE(r.ok) << n;
    EXPECT_NEAR(r.s, 1.0 / (n + 1), 1e-12) << n;
    for (double d : r.d) EXPECT_NEAR(d, 1.0 / (n + 1), 1e-12) << n;
    // A box smaller than the optimum binds: every d_i = box, s = box.
    const opt::MaxMinN c = opt::max_min_affine(n, a, b, w, std::vector<double>(n, 0.5 / (n + 1)));
    EXPECT_NEAR(c.s, 0.5 / (n + 1), 1e-12) << n;
  }
  // Weights: d >= 2 s and 1 − d >= s give d = 2/3, s = 1/3.
  const opt::MaxMinN r = opt::max_min_affine(1, {1.0, -1.0}, {0.0, 1.0}, {2.0, 1.0}, {1.0});
  EXPECT_NEAR(r.s, 1.0 / 3, 1e-12);
  EXPECT_NEAR(r.d[0], 2.0 / 3, 1e-12);
}

// Four pillow hexes of cthead's bone at iso 1200, h 5, at a dart-shaped boundary quad (their
// boundary vertices free here, in space). The single moves run until no vertex moves (0.190 ->
// 0.194); from there, moving the patch's vertices together still lifts the cluster (to 0.208),
// every hex certified, the smallest scaled Jacobian not lowered, no hex more below 0.2. (With
// the boundary vertices held neither gains anything.)
TEST(OptimizePatch, JointMovesGoOnWhereSingleMovesStop) {
  std::vector<Index> targets;
  const HexMesh before = bone_cluster(targets, true);
  ASSERT_EQ(before.num_hexes(), 31);
  ASSERT_EQ(targets.size(), 4u);
  HexMesh stalled = before;
  const WorstResult s = test::stall_single_moves(stalled, 500);
  ASSERT_LT(s.passes, 500);  // it stopped: no single move gains
  const double stalled_rank = lowest_rank(stalled, targets);
  ASSERT_LT(stalled_rank, 0.25);

  HexMesh joint = stalled;
  WorstOptions joint_only;
  joint_only.search_trials = 0;
  const WorstResult r = improve_worst(joint, joint.fixed, joint_only);
  EXPECT_GT(r.patch_moves, 0u);
  const double joint_rank = lowest_rank(joint, targets);
  EXPECT_GT(joint_rank, stalled_rank + 0.005);
  std::size_t below_before = 0, below_after = 0;
  for (Index h = 0; h < before.num_hexes(); ++h) {
    EXPECT_TRUE(certified_valid(joint.corners(h), 0.0)) << h;
    below_before += certified_scaled_jacobian(stalled.corners(h)) < 0.2;
    below_after += certified_scaled_jacobian(joint.corners(h)) < 0.2;
  }
  EXPECT_LE(below_after, below_before);
  EXPECT_GE(min_certified_sj(joint), min_certified_sj(stalled));
  for (Index v = 0; v < before.num_vertices(); ++v)
    if (before.fixed[v]) EXPECT_EQ(joint.points[v], before.points[v]);
  std::printf("start %.4f, single moves %.4f, joint %.4f (%zu joint moves)\n", lowest_rank(before, targets),
              stalled_rank, joint_rank, r.patch_moves);
}

// move_patch() on its own: whatever it does, it keeps its guards (property test on jittered
// pieces of the same cluster).
TEST(OptimizePatch, MovesKeepTheirGuards) {
  std::vector<Index> targets, patch;
  std::size_t moved = 0, moved_guarded = 0;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    HexMesh m = jittered_bone(seed, targets, patch);
    const Incidence inc = vertex_hexes(m);
    const HexMesh before = m;
    const double lo = min_certified_sj(before);
    std::size_t below0 = 0;
    for (Index h = 0; h < m.num_hexes(); ++h) below0 += certified_scaled_jacobian(m.corners(h)) < 0.2;
    // Seeds 7-12: the guarded model (move_patch()'s second try in the worst pass).
    if (!opt::move_patch(m, inc, targets, patch, before.points, WorstOptions{}, lo,
                         seed > 6 ? opt::PatchModels::guarded : opt::PatchModels::plain))
      continue;
    ++moved;
    moved_guarded += seed > 6;
    std::size_t below = 0;
    for (Index h = 0; h < m.num_hexes(); ++h) {
      EXPECT_TRUE(certified_valid(m.corners(h), 0.0)) << seed << " " << h;
      below += certified_scaled_jacobian(m.corners(h)) < 0.2;
    }
    EXPECT_LE(below, below0) << seed;
    EXPECT_GE(min_certified_sj(m), lo - 1e-12) << seed;
    for (Index v = 0; v < m.num_vertices(); ++v)
      if (m.fixed[v]) EXPECT_EQ(m.points[v], before.points[v]);
  }
  EXPECT_GT(moved, moved_guarded);
  EXPECT_GT(moved_guarded, 0u);
}

// The worst pass's tries (PatchModels::both) leave the mesh as the plain model and, where it
// gains nothing, the guarded one do, bit for bit: the guarded model is skipped only where it is
// the plain one's LP (on these pieces, every seed the plain model could not move). Fails if
// the skip drops a guarded model that differs.
TEST(OptimizePatch, BothModelsGiveThePlainThenGuardedBits) {
  std::vector<Index> targets, patch;
  int plain_failed = 0;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    HexMesh start = jittered_bone(seed, targets, patch);
    const Incidence inc = vertex_hexes(start);
    // The plain model's moves until they stop (or five), as the worst pass meets the patch.
    const std::vector<Vec3> jittered = start.points;
    for (int k = 0; k < 5 && opt::move_patch(start, inc, targets, patch, jittered, {}, min_certified_sj(start)); ++k) {
    }
    const double lo = min_certified_sj(start);
    for (const double sj_floor : {0.2, 0.3}) {  // the floor decides which rows differ
      WorstOptions options;
      options.sj_floor = sj_floor;
      HexMesh both = start, apart = start;
      const bool b = opt::move_patch(both, inc, targets, patch, jittered, options, lo, opt::PatchModels::both);
      bool a = opt::move_patch(apart, inc, targets, patch, jittered, options, lo, opt::PatchModels::plain);
      plain_failed += !a;
      a = a || opt::move_patch(apart, inc, targets, patch, jittered, options, lo, opt::PatchModels::guarded);
      EXPECT_EQ(a, b) << seed;
      for (Index v = 0; v < start.num_vertices(); ++v)
        for (int d = 0; d < 3; ++d) EXPECT_EQ(both.points[v][d], apart.points[v][d]) << seed << " " << v;
    }
  }
  EXPECT_GT(plain_failed, 0);
}

// `isohex smooth --patch-rounds` (the shape stage off, as the band rounds find the cluster): the
// joint moves are counted in the JSON report, 0 turns them
// off, and a value out of range exits 2 before anything is written.
TEST(OptimizePatch, CliSmoothCountsJointMovesAndRefusesABadValue) {
  EXPECT_GT(test::smooth_piece_count("bone_cluster.txt", "", "patch_moves"), 0u);
  EXPECT_EQ(test::smooth_piece_count("bone_cluster.txt", " --patch-rounds 0", "patch_moves"), 0u);
  test::expect_smooth_refuses("bone_cluster.txt", "--patch-rounds", "-1");
}

// The single passes' stall stop (WorstOptions::stall_passes) ends them where ten passes gain
// less than stall_gain; it cuts the run short and changes nothing else: the same passes without
// the stop give the same mesh, bit for bit, and running on to the end gains little.
TEST(OptimizePatch, SinglePassesStopWhenTheyStall) {
  std::vector<Index> targets;
  const HexMesh before = test::read_piece("bone_stall.txt", targets, true);  // single moves creep on here
  WorstOptions single;
  single.patch_rounds = 0;
  single.search_trials = 0;
  single.passes = 1000;
  HexMesh stopped = before;
  const WorstResult s = improve_worst(stopped, stopped.fixed, single);
  single.stall_passes = 0;
  HexMesh full = before;
  const WorstResult f = improve_worst(full, full.fixed, single);
  EXPECT_LT(s.passes, f.passes);
  EXPECT_GT(s.passes_seconds, 0.0);  // all of its time, with no joint moves and no walk
  EXPECT_EQ(s.patch_seconds, 0.0);
  EXPECT_EQ(s.search_seconds, 0.0);
  single.passes = s.passes;
  HexMesh prefix = before;
  improve_worst(prefix, prefix.fixed, single);
  EXPECT_EQ(prefix.points, stopped.points);
  EXPECT_GE(s.min_sj_after, s.min_sj_before);
  EXPECT_GT(lowest_rank(stopped, targets), lowest_rank(full, targets) - 0.01);
  std::printf("stopped after %d passes at %.4f; to the end %d passes, %.4f\n", s.passes, lowest_rank(stopped, targets),
              f.passes, lowest_rank(full, targets));
}

// The single passes after a round of joint moves stop at a stall over resume_stall_passes (3):
// fewer passes than running each batch's ten (the old rule), the joint moves still made, and no
// lower a minimum.
TEST(OptimizePatch, PassesAfterJointMovesStopAtAShorterStall) {
  std::vector<Index> targets;
  const HexMesh before = bone_cluster(targets, true);
  WorstOptions o;
  o.search_trials = 0;  // the joint moves' rounds alone
  HexMesh shorter = before;
  const WorstResult s = improve_worst(shorter, shorter.fixed, o);
  o.resume_stall_passes = o.stall_passes;
  HexMesh longer = before;
  const WorstResult l = improve_worst(longer, longer.fixed, o);
  EXPECT_GT(s.patch_moves, 0u);
  EXPECT_LT(s.passes, l.passes);
  EXPECT_GE(s.min_sj_after, s.min_sj_before);
  EXPECT_GE(lowest_rank(shorter, targets), lowest_rank(longer, targets) - 1e-9);
  std::printf("after joint moves: %d passes, lowest rank %.4f; with batches of ten %d passes, %.4f\n", s.passes,
              lowest_rank(shorter, targets), l.passes, lowest_rank(longer, targets));
}

// The joint moves' memo (WorstOptions::patch_memo): a cluster whose tries all failed is not
// tried again while nothing they read has changed. Two copies of the bone's cluster side by
// side, one with its boundary held (its joint moves fail), one free (they succeed, so the
// rounds go on): the held one is skipped, and the mesh is the same, bit for bit, as trying it
// again each round. (Here nothing moves near the held cluster, so a memo that also skipped
// clusters whose surroundings had moved would pass too; the pieces in tests/data have no such
// case. The whole pipeline on headsq, iso 800, h 3, skipped 15 clusters and wrote the same
// bytes as the build without the memo: docs/benchmarks.md.)
TEST(OptimizePatch, FailedClustersAreSkippedWithTheSameMesh) {
  std::vector<Index> targets;
  HexMesh both = bone_cluster(targets, false);
  const HexMesh free_copy = bone_cluster(targets, true);
  const Index offset = both.num_vertices();
  for (const Vec3& p : free_copy.points) both.points.push_back(p + Vec3(1000, 0, 0));
  both.fixed.insert(both.fixed.end(), free_copy.fixed.begin(), free_copy.fixed.end());
  for (Hex h : free_copy.hexes) {
    for (Index& v : h) v += offset;
    both.hexes.push_back(h);
  }
  WorstOptions o;
  o.search_trials = 0;
  HexMesh with = both, without = both;
  const WorstResult a = improve_worst(with, with.fixed, o);
  o.patch_memo = false;
  const WorstResult b = improve_worst(without, without.fixed, o);
  EXPECT_GT(a.patch_moves, 0u);
  EXPECT_GT(a.patch_skipped, 0u);
  EXPECT_EQ(b.patch_skipped, 0u);
  EXPECT_EQ(a.patch_moves, b.patch_moves);
  EXPECT_EQ(with.points, without.points);
  std::printf("%zu joint moves, %zu clusters skipped\n", a.patch_moves, a.patch_skipped);
}
