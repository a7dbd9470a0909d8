// OrderedMoves: a sequence of vertex moves run in parallel with the sequence's own result; the
// worst pass that runs on it.
#include "isohex/mesh/generate.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/ordered_moves.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

using namespace isohex;

namespace {

// A move that reads every vertex of the hexes around v, non-linearly: moves that share a hex
// do not commute, so any order but the sequence's (or a wrong level) changes the bits.
Vec3 neighbour_move(const HexMesh& m, const Incidence& inc, Index v) {
  Vec3 sum = Vec3::Zero();
  int n = 0;
  for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k)
    for (Index w : m.hexes[inc.ids[k]])
      if (w != v) sum += m.points[w] * (1 + 0.1 * std::sin(m.points[w].sum())), ++n;
  return 0.5 * m.points[v] + 0.5 * sum / n;
}

}  // namespace

TEST(OrderedMoves, RunsAsTheSequenceForAnyThreadCount) {
  HexMesh start = box_mesh(7, 7, 7);
  jitter(start, 0.05, 3);
  const Incidence inc = vertex_hexes(start);
  // Half the vertices in a shuffled order, so that neighbours come both before and after.
  std::vector<Index> seq(static_cast<std::size_t>(start.num_vertices()));
  std::iota(seq.begin(), seq.end(), 0);
  std::shuffle(seq.begin(), seq.end(), std::mt19937(11));
  seq.resize(seq.size() / 2);

  HexMesh serial = start;
  for (Index v : seq) serial.points[v] = neighbour_move(serial, inc, v);

  for (int threads : {1, 2, 4}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    HexMesh m = start;
    opt::OrderedMoves moves(m, inc);
    for (Index v : seq) moves.add(v);
    ASSERT_EQ(moves.size(), seq.size());
    for (std::size_t k = 0; k < seq.size(); ++k) ASSERT_EQ(moves.position(seq[k]), static_cast<Index>(k));
    std::vector<Vec3> next(seq.size());
    std::vector<std::size_t> committed;
    moves.run([&](std::size_t k) { next[k] = neighbour_move(m, inc, moves.vertex(k)); },
              [&](std::size_t k) {
                m.points[moves.vertex(k)] = next[k];  // the commit publishes the move
                committed.push_back(k);
              });
    EXPECT_EQ(committed.size(), seq.size());
    EXPECT_EQ(m.points, serial.points) << threads << " threads";
    // A level runs in parallel only when it has more than one move: not all in sequence order.
    EXPECT_FALSE(std::is_sorted(committed.begin(), committed.end()));
    moves.clear();
    EXPECT_EQ(moves.size(), 0u);
    EXPECT_EQ(moves.position(seq[0]), -1);
  }
}

TEST(OrderedMoves, WorstPassIsTheSameForAnyThreadCount) {
  HexMesh start = box_mesh(8, 8, 8);
  jitter(start, 0.3 / 8, 5);
  start.fixed = boundary_vertex_mask(start);
  optimize_shape(start, start.fixed);
  std::vector<Vec3> out[2];
  WorstResult res[2];
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    HexMesh m = start;
    res[threads - 1] = improve_worst(m, m.fixed, WorstOptions{.below = 1.5, .count = 200, .raise_below = 0.6});
    out[threads - 1] = m.points;
  }
  EXPECT_GT(res[0].moves, 100u);
  EXPECT_EQ(res[0].moves, res[1].moves);
  EXPECT_EQ(res[0].passes, res[1].passes);
  EXPECT_EQ(out[0], out[1]);
  EXPECT_GT(res[0].min_sj_after, res[0].min_sj_before);
}
