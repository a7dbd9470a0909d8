#pragma once
/// \file ordered_moves.hpp
/// \brief Internal to optimize/: a sequence of single-vertex moves run in parallel with the
/// result of running them one after another.
///
/// A move of vertex v reads the places of the vertices of the hexes around v and writes v's
/// own. Two moves whose vertices share no hex therefore commute, and a move needs to wait only
/// for the moves earlier in the sequence whose vertices share a hex with its own. Each move
/// gets a level, one above the highest level among those; a level's moves run in parallel, the
/// levels in order. Every move sees exactly what it would see in the sequence, so the result is
/// the sequential one, bit for bit, for any thread count.

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/mesh/topology.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>
#include <vector>

namespace isohex::opt {

class OrderedMoves {
 public:
  OrderedMoves(const HexMesh& mesh, const Incidence& inc) : mesh_(mesh), inc_(inc), at_(mesh.points.size(), -1) {}

  /// The level a move of v would get: 0 when no move in the sequence shares a hex with v.
  [[nodiscard]] int level_of(Index v) const {
    int level = 0;
    for (Index k = inc_.offsets[v]; k < inc_.offsets[v + 1]; ++k)
      for (Index w : mesh_.hexes[inc_.ids[k]])
        if (const Index a = at_[w]; a >= 0 && level_[static_cast<std::size_t>(a)] >= level)
          level = level_[static_cast<std::size_t>(a)] + 1;
    return level;
  }
  /// Appends a move of v to the sequence (a vertex at most once until clear()).
  void add(Index v) { add(v, level_of(v)); }
  /// The same with v's level_of() known.
  void add(Index v, int level) {
    at_[v] = static_cast<Index>(moves_.size());
    if (static_cast<std::size_t>(level) >= levels_.size()) levels_.resize(static_cast<std::size_t>(level) + 1);
    levels_[static_cast<std::size_t>(level)].push_back(moves_.size());
    moves_.push_back(v);
    level_.push_back(level);
  }
  [[nodiscard]] std::size_t size() const { return moves_.size(); }
  [[nodiscard]] Index vertex(std::size_t k) const { return moves_[k]; }
  /// The place of v's move in the sequence, -1 when v has none.
  [[nodiscard]] Index position(Index v) const { return at_[v]; }

  /// Runs the moves: attempt(k) for the k-th move of the sequence (concurrently with moves of
  /// its level: it may write only its own vertex and per-move slots), then, once its level is
  /// done, commit(k) for each of the level's moves in sequence order (single-threaded: what a
  /// move changes for the moves after it that share a hex with it).
  template <class Attempt, class Commit>
  void run(Attempt&& attempt, Commit&& commit) const {
    for (const std::vector<std::size_t>& level : levels_) {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, level.size(), 1), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) attempt(level[i]);
      });
      for (std::size_t k : level) commit(k);
    }
  }

  /// Empties the sequence.
  void clear() {
    for (Index v : moves_) at_[v] = -1;
    moves_.clear();
    level_.clear();
    levels_.clear();
  }

 private:
  const HexMesh& mesh_;
  const Incidence& inc_;
  std::vector<Index> at_;  // per vertex: its move's place in the sequence, -1 when none
  std::vector<Index> moves_;
  std::vector<int> level_;  // per move
  std::vector<std::vector<std::size_t>> levels_;
};

}  // namespace isohex::opt
