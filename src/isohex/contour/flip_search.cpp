// The manifold repair's simple flips: of the samples at L == 0 whose cells would put their
// vertices on them (fill_zero_level_samples), and the searches for sequences of simple flips
// (short, prepared and deep; FlipSearch) with the phase that runs them over the non-manifold cells.
#include "isohex/contour/cell_cases.hpp"
#include "isohex/contour/repair_internal.hpp"
#include "isohex/contour/simple_point.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace isohex::contour {

namespace {

int non_manifold_around(const SampledGrid& g, std::size_t p) {
  int n = 0;
  for (std::size_t cell : cells_around(g, p)) n += !cell_case(g.cell_mask_at(cell)).manifold;
  return n;
}

}  // namespace

// Not padding, and next to the isosurface: some 26-neighbour was sampled on the other side
// (the level's sign is the sample's own side). Flipping a point away from the surface would
// leave its dual vertices no surface to be projected onto.
bool near_surface(const SampledGrid& g, std::size_t p) {
  const std::size_t dy = g.padded[0], dz = g.padded[0] * g.padded[1];
  if (g.is_padding(p % dy, p / dy % g.padded[1], p / dz)) return false;
  const bool in = g.level[p] > 0;
  for (int z = -1; z <= 1; ++z)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x) {
        const std::size_t q = p + static_cast<std::size_t>(x) + dy * static_cast<std::size_t>(y) + dz * static_cast<std::size_t>(z);
        if ((g.level[q] > 0) != in) return true;
      }
  return false;
}

namespace {

// A search for a short sequence of simple flips (each simple in the state the ones before
// it leave) that lowers the number of non-manifold cells. The first flip is a corner of the
// target cell, each later one a corner of a non-manifold cell next to the flip before it.
// The short search takes any sequence of up to kMaxDepth flips; the deep one, run only where
// the short one found nothing, sequences of up to kDeepDepth flips each of which mends the
// cell it is a corner of without raising the number (a defect walked along a structure, e.g.
// two one-sample-thick fingers joined at their base, zipped up to their tips one fill at a
// time), which keeps its branching small; it stops after kDeepBudget simple-point tests.
class FlipSearch {
 public:
  static constexpr int kMaxDepth = 5;
  static constexpr int kDeepDepth = 32;
  static constexpr long kDeepBudget = 20000;  // simple-point tests per cell, all depths
  explicit FlipSearch(SampledGrid& g) : g_(g), dy_(g.padded[0]), dz_(g.padded[0] * g.padded[1]) {}

  // Finds and applies the best sequence for `cell` (fewest flips, then lowest sum of |level|);
  // returns its length, 0 if none.
  int repair(std::size_t cell) { return run(cell, 1, kMaxDepth, false); }
  // The same with the deep search (sequences of kMaxDepth + 1 to kDeepDepth flips).
  int repair_deep(std::size_t cell) { return run(cell, kMaxDepth + 1, kDeepDepth, true); }
  // The same with prepared flips: a corner of the cell that is not simple is made simple by
  // flipping points next to it first. Sequences p1, ..., pn (n = 2 .. kPrepDepth) with pn a
  // corner of the cell and each p(i) a 26-neighbour of p(i+1), e.g. the tip of a
  // one-sample-thick finger and then its last point, which is a corner; or an inside point
  // next to a one-sample cavity and then the cavity (the cavity moved by one).
  int repair_prepared(std::size_t cell) {
    best_len_ = 0;
    best_score_ = std::numeric_limits<double>::infinity();
    for (int n = 2; n <= kPrepDepth && best_len_ == 0; ++n)
      for (int c = 0; c < 8; ++c) {
        const std::size_t p = g_.corner_at(cell, c);
        if (!flippable(p)) continue;
        path_[static_cast<std::size_t>(n - 1)] = p;
        chain(n - 2, n, std::abs(static_cast<double>(g_.level[p])));
      }
    for (int s = 0; s < best_len_; ++s) g_.inside[best_[static_cast<std::size_t>(s)]] ^= 1;
    return best_len_;
  }
  static constexpr int kPrepDepth = 3;
  const std::size_t* flips() const { return best_.data(); }

 private:
  // Chooses path_[i] among the 26-neighbours of path_[i + 1], down to path_[0]; then tries
  // the sequence path_[0..n).
  void chain(int i, int n, double score) {
    if (i < 0) {
      try_sequence(n, score);
      return;
    }
    const std::size_t next = path_[static_cast<std::size_t>(i + 1)];
    for (int z = -1; z <= 1; ++z)
      for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
          if (x == 0 && y == 0 && z == 0) continue;
          const std::size_t q = next + static_cast<std::size_t>(x) + dy_ * static_cast<std::size_t>(y) + dz_ * static_cast<std::size_t>(z);
          if (std::find(path_.begin() + i + 1, path_.begin() + n, q) != path_.begin() + n || !flippable(q)) continue;
          const double sc = score + std::abs(static_cast<double>(g_.level[q]));
          if (!(sc < best_score_)) continue;
          path_[static_cast<std::size_t>(i)] = q;
          chain(i - 1, n, sc);
        }
  }

  // Flips path_[0..n) in order while each is simple; kept as the best when all are and the
  // number of non-manifold cells fell. The grid is restored.
  void try_sequence(int n, double score) {
    int k = 0, d = 0;
    for (; k < n; ++k) {
      const std::size_t p = path_[static_cast<std::size_t>(k)];
      if (!simple_at(g_, p)) break;
      const int before = non_manifold_around(g_, p);
      g_.inside[p] ^= 1;
      d += non_manifold_around(g_, p) - before;
    }
    if (k == n && d < 0) {
      best_ = path_;
      best_len_ = n;
      best_score_ = score;
    }
    while (k-- > 0) g_.inside[path_[static_cast<std::size_t>(k)]] ^= 1;
  }

  int run(std::size_t cell, int from, int to, bool monotone) {
    best_len_ = 0;
    best_score_ = std::numeric_limits<double>::infinity();
    monotone_ = monotone;
    nodes_ = 0;
    for (int depth = from; depth <= to && best_len_ == 0; ++depth) {
      max_depth_ = depth;
      search({cell}, 0, 0, 0.0);
    }
    for (int s = 0; s < best_len_; ++s) g_.inside[best_[static_cast<std::size_t>(s)]] ^= 1;
    return best_len_;
  }

  bool flippable(std::size_t p) const { return near_surface(g_, p); }

  void search(const std::vector<std::size_t>& cells, int len, int delta, double score) {
    for (std::size_t cell : cells)
      for (int c = 0; c < 8; ++c) {
        const std::size_t p = g_.corner_at(cell, c);
        if (!flippable(p) || std::find(path_.begin(), path_.begin() + len, p) != path_.begin() + len) continue;
        const double sc = score + std::abs(static_cast<double>(g_.level[p]));
        if (!(sc < best_score_)) continue;
        if (monotone_ && ++nodes_ > kDeepBudget) return;
        if (!simple_at(g_, p)) continue;
        const int before = non_manifold_around(g_, p);
        g_.inside[p] ^= 1;
        const int after = non_manifold_around(g_, p);
        path_[static_cast<std::size_t>(len)] = p;
        const int d = delta + after - before;
        // The deep search walks the defect: the flip must mend the cell it is a corner of
        // without raising the count.
        if (monotone_ && (d > 0 || (d == 0 && !cell_case(g_.cell_mask_at(cell)).manifold))) {
          g_.inside[p] ^= 1;
          continue;
        }
        if (d < 0) {
          best_ = path_;
          best_len_ = len + 1;
          best_score_ = sc;
        } else if (len + 1 < max_depth_) {
          std::vector<std::size_t> next;
          for (std::size_t q : cells_around(g_, p))
            if (!cell_case(g_.cell_mask_at(q)).manifold) next.push_back(q);
          if (!next.empty()) search(next, len + 1, d, sc);
        }
        g_.inside[p] ^= 1;
      }
  }

  SampledGrid& g_;
  std::size_t dy_, dz_;
  int max_depth_ = 1, best_len_ = 0;
  bool monotone_ = false;
  long nodes_ = 0;  // simple-point tests of the deep search so far
  double best_score_ = 0;
  std::array<std::size_t, kDeepDepth> path_{}, best_{};
};

}  // namespace

std::size_t simple_phase(SampledGrid& g, RepairCounts& counts, Search mode, std::vector<std::size_t>& cells) {
  FlipSearch search(g);
  std::size_t total = 0;
  for (;;) {
    ++counts.rounds;
    const std::size_t from = counts.edits.size();
    for (std::size_t cell : cells) {
      if (cell_case(g.cell_mask_at(cell)).manifold) continue;  // an earlier flip fixed it
      const int n = mode == Search::short_     ? search.repair(cell)
                    : mode == Search::prepared ? search.repair_prepared(cell)
                                               : search.repair_deep(cell);
      for (int s = 0; s < n; ++s) {
        ++(g.inside[search.flips()[s]] ? counts.filled : counts.carved);
        counts.edits.push_back({search.flips()[s], RepairKind::simple});
      }
    }
    const std::size_t flips = counts.edits.size() - from;
    cells = still_non_manifold(g, std::move(cells), counts, from);
    counts.simple += flips;
    total += flips;
    if (flips == 0 || mode != Search::short_) return total;
  }
}

namespace {

// True when every crossing of cell `cell` is at sample q. dual_contour.cpp finds a crossing on
// each edge from an inside corner at L > 0 to an outside one at L <= 0, at that outside corner
// when it is at L == 0; with all of them at q the cell's dual vertex goes onto q.
bool pinned_to(const SampledGrid& g, std::size_t cell, std::size_t q) {
  const std::uint8_t m = g.cell_mask_at(cell);
  bool any = false;
  for (int c = 0; c < 8; ++c) {
    const std::size_t p = g.corner_at(cell, c);
    if (!(m >> c & 1) || !(g.level[p] > 0)) continue;
    for (int a = 0; a < 3; ++a) {
      const int d = c ^ (1 << a);
      const std::size_t r = g.corner_at(cell, d);
      if ((m >> d & 1) || g.level[r] > 0) continue;  // no crossing on this edge
      if (r != q) return false;
      any = true;
    }
  }
  return any;
}

// True when the only zeros of cell `cell` are at its inside corner q (L == 0): every edge from
// an inside corner to an outside one ends at a carved sample (L > 0, no crossing there), and q
// is the only inside corner at L <= 0. dual_contour.cpp then takes the zeros on the inside
// corners' edges, which are all q.
bool loose_pinned_to(const SampledGrid& g, std::size_t cell, std::size_t q) {
  const std::uint8_t m = g.cell_mask_at(cell);
  bool any = false;
  for (int c = 0; c < 8; ++c) {
    const std::size_t p = g.corner_at(cell, c);
    if (!(m >> c & 1)) continue;
    if (!(g.level[p] > 0) && p != q) return false;
    for (int a = 0; a < 3; ++a) {
      const int d = c ^ (1 << a);
      if (m >> d & 1) continue;
      if (!(g.level[g.corner_at(cell, d)] > 0)) return false;
      any = true;
    }
  }
  return any;
}

// More than one cell around outside sample q at L == 0 has its dual vertex on q.
bool shared_pin(const SampledGrid& g, std::size_t q) {
  int n = 0;
  for (std::size_t cell : cells_around(g, q)) n += pinned_to(g, cell, q);
  return n > 1;
}

}  // namespace

std::size_t fill_zero_level_samples(SampledGrid& g, RepairCounts& counts) {
  const std::vector<std::size_t> candidates = zero_level_outside(g);
  if (candidates.empty()) return 0;
  // Sequential, in grid order, in rounds (a fill can make a neighbour simple: the end of a
  // chain of such samples first) until one fills nothing: the same for any thread count.
  std::size_t total = 0;
  for (std::size_t filled = 1; filled;) {
    ++counts.rounds;
    filled = 0;
    for (std::size_t p : candidates) {
      if (g.inside[p] || !shared_pin(g, p) || !simple_at(g, p)) continue;
      const int before = non_manifold_around(g, p);
      g.inside[p] = 1;
      if (non_manifold_around(g, p) > before) {
        g.inside[p] = 0;
        continue;
      }
      counts.edits.push_back({p, RepairKind::zero_level});
      ++filled;
    }
    total += filled;
  }
  counts.filled += total;
  counts.zero_level += total;
  return total;
}

std::size_t fill_shared_pins(SampledGrid& g, RepairCounts& counts) {
  std::size_t total = 0;
  auto fill = [&](std::size_t p) {
    g.inside[p] = 1;
    counts.edits.push_back({p, RepairKind::pinch});
    ++total;
  };
  for (std::size_t p : zero_level_outside(g))
    if (!g.inside[p] && shared_pin(g, p)) fill(p);
  for (std::size_t q : zero_level_samples(g, 1)) {
    std::array<std::size_t, 8> pinned{};
    int n = 0;
    for (std::size_t cell : cells_around(g, q))
      if (loose_pinned_to(g, cell, q)) pinned[static_cast<std::size_t>(n++)] = cell;
    if (n < 2) continue;
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 8; ++c) {
        const std::size_t p = g.corner_at(pinned[static_cast<std::size_t>(i)], c);
        if (!g.inside[p]) fill(p);
      }
  }
  counts.pinch += total;
  return total;
}

}  // namespace isohex::contour
