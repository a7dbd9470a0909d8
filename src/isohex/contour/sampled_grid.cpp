#include "isohex/contour/sampled_grid.hpp"

#include "isohex/contour/cell_cases.hpp"
#include "isohex/contour/handle_move.hpp"
#include "isohex/contour/simple_point.hpp"
#include "isohex/error.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace isohex::contour {

std::uint8_t SampledGrid::cell_mask_at(std::size_t cell) const {
  const std::size_t dy = padded[0], dz = padded[0] * padded[1];
  const std::uint8_t* p = inside.data() + cell;
  return static_cast<std::uint8_t>(p[0] | p[1] << 1 | p[dy] << 2 | p[dy + 1] << 3 | p[dz] << 4 | p[dz + 1] << 5 |
                                   p[dz + dy] << 6 | p[dz + dy + 1] << 7);
}

std::uint8_t SampledGrid::padding_mask(std::size_t i, std::size_t j, std::size_t k) const {
  std::uint8_t m = 0;
  for (int c = 0; c < 8; ++c)
    if (is_padding(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1))) m |= static_cast<std::uint8_t>(1u << c);
  return m;
}

SampledGrid sample_region(const Region& region, const DualGrid& grid) {
  SampledGrid g;
  g.grid = grid;
  g.domain = region.domain;
  double total = 1;
  for (int a = 0; a < 3; ++a) {
    g.padded[a] = static_cast<std::size_t>(grid.points[a]) + 2;
    total *= static_cast<double>(g.padded[a]);
  }
  if (total > static_cast<double>(std::numeric_limits<Index>::max()))
    throw Error(fmt::format("a grid of {} x {} x {} points is too large (over 2^31 points); use a larger cell size",
                            grid.points[0], grid.points[1], grid.points[2]));
  g.inside.assign(static_cast<std::size_t>(total), 0);
  g.level.assign(static_cast<std::size_t>(total), 0.0f);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(1, g.padded[2] - 1), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k)
      for (std::size_t j = 1; j + 1 < g.padded[1]; ++j)
        for (std::size_t i = 1; i + 1 < g.padded[0]; ++i) {
          const Vec3 p = g.position(i, j, k);
          double l = std::numeric_limits<double>::infinity();
          for (const LevelSet& s : region.surfaces) l = std::min(l, s.level(p));
          const bool in = l > 0;  // L == 0 (and NaN) is outside
          g.inside[g.index(i, j, k)] = in;
          // Exact zeros are +0 and only they (fill_degenerate_cavities); NaN is -0.
          float lf = static_cast<float>(l);
          if (std::isnan(l)) lf = -0.0f;
          else if (l == 0) lf = 0.0f;
          else if (lf == 0.0f) lf = std::copysign(std::numeric_limits<float>::denorm_min(), static_cast<float>(l > 0 ? 1 : -1));
          g.level[g.index(i, j, k)] = lf;
        }
  });
  return g;
}

namespace {

// Rounds of one repair phase: `edit(mask, i, j, k)` gives the corners of cell (i, j, k) to
// flip to `to`; the slabs of the non-manifold cells in `start` (all there are) are checked,
// then only the slabs around flipped points, until a round flips nothing. Proposals are gathered before any is applied, so the result does not
// depend on the thread count. Returns the points flipped and adds the rounds to `rounds`.
template <typename Edit>
std::size_t repair_phase(SampledGrid& g, std::uint8_t to, const std::vector<std::size_t>& start, RepairCounts& counts,
                         Edit&& edit) {
  std::size_t& rounds = counts.rounds;
  const std::size_t nk = g.num_cells(2);
  std::vector<std::uint8_t> dirty(nk, 0);
  for (std::size_t cell : start) dirty[cell / (g.padded[0] * g.padded[1])] = 1;
  std::vector<std::vector<std::size_t>> flips(nk);
  std::size_t total = 0;
  for (;;) {
    ++rounds;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nk), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t k = r.begin(); k != r.end(); ++k) {
        flips[k].clear();
        if (!dirty[k]) continue;
        for (std::size_t j = 0; j < g.num_cells(1); ++j)
          for (std::size_t i = 0; i < g.num_cells(0); ++i) {
            const std::uint8_t m = g.cell_mask(i, j, k);
            if (cell_case(m).manifold) continue;
            const std::uint8_t f = edit(m, i, j, k);
            for (int c = 0; c < 8; ++c)
              if (f & (1u << c)) flips[k].push_back(g.index(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1)));
          }
      }
    });
    std::fill(dirty.begin(), dirty.end(), 0);
    std::size_t changed = 0;
    const std::size_t plane = g.padded[0] * g.padded[1];
    for (const auto& slab : flips)
      for (std::size_t p : slab) {
        if (g.inside[p] == to) continue;  // two cells asked for the same point
        g.inside[p] = to;
        counts.edits.push_back({p, RepairKind::forced});
        ++changed;
        const std::size_t pk = p / plane;  // the point touches cell slabs pk - 1 and pk
        if (pk > 0) dirty[pk - 1] = 1;
        if (pk < nk) dirty[pk] = 1;
      }
    total += changed;
    if (changed == 0) return total;
  }
}

// True when making inside point p outside leaves the inside points around it connected: the
// inside points of its 18-neighbourhood that are face-adjacent to p form one part under
// face adjacency within that neighbourhood. Carving such a point opens the outside without
// cutting a bridge or deleting an isolated point.
bool carving_keeps_inside_connected(const SampledGrid& g, std::size_t p) {
  const std::ptrdiff_t sy = static_cast<std::ptrdiff_t>(g.padded[0]), sz = sy * static_cast<std::ptrdiff_t>(g.padded[1]);
  // n[x][y][z] for offsets -1..1; corners of the 3x3x3 block are not in the 18-neighbourhood.
  bool in[27] = {};
  auto at = [](int x, int y, int z) { return (x + 1) + 3 * (y + 1) + 9 * (z + 1); };
  for (int z = -1; z <= 1; ++z)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x) {
        if ((x == 0 && y == 0 && z == 0) || (x && y && z)) continue;
        in[at(x, y, z)] = g.inside[static_cast<std::size_t>(static_cast<std::ptrdiff_t>(p) + x + sy * y + sz * z)] != 0;
      }
  int label[27];
  std::fill(std::begin(label), std::end(label), -1);
  int parts = 0;
  static constexpr int kFaces[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const auto& f : kFaces) {
    const int seed = at(f[0], f[1], f[2]);
    if (!in[seed] || label[seed] >= 0) continue;
    if (++parts > 1) return false;
    int stack[27], top = 0;
    stack[top++] = seed;
    label[seed] = 0;
    while (top) {
      const int q = stack[--top];
      const int qx = q % 3 - 1, qy = q / 3 % 3 - 1, qz = q / 9 - 1;
      for (const auto& d : kFaces) {
        const int x = qx + d[0], y = qy + d[1], z = qz + d[2];
        if (x < -1 || x > 1 || y < -1 || y > 1 || z < -1 || z > 1) continue;
        const int r = at(x, y, z);
        if (in[r] && label[r] < 0) {
          label[r] = 0;
          stack[top++] = r;
        }
      }
    }
  }
  return parts == 1;
}

// The 8 cells around padded point p (never padding), by the index of their lowest corner.
std::array<std::size_t, 8> cells_around(const SampledGrid& g, std::size_t p) {
  const std::size_t dy = g.padded[0], dz = g.padded[0] * g.padded[1];
  std::array<std::size_t, 8> cells{};
  for (int c = 0; c < 8; ++c) cells[static_cast<std::size_t>(c)] = p - (c & 1) - dy * (c >> 1 & 1) - dz * (c >> 2 & 1);
  return cells;
}

int non_manifold_around(const SampledGrid& g, std::size_t p) {
  int n = 0;
  for (std::size_t cell : cells_around(g, p)) n += !cell_case(g.cell_mask_at(cell)).manifold;
  return n;
}

bool simple_at(const SampledGrid& g, std::size_t p) {
  const std::size_t dy = g.padded[0], dz = g.padded[0] * g.padded[1];
  Neighbourhood nb{};
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 3; ++x)
        nb[static_cast<std::size_t>(x + 3 * y + 9 * z)] = g.inside[p + x + dy * y + dz * z - 1 - dy - dz] != 0;
  return is_simple_6_18(nb);
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
        const std::size_t p = cell + (c & 1) + dy_ * (c >> 1 & 1) + dz_ * (c >> 2 & 1);
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
        const std::size_t p = cell + (c & 1) + dy_ * (c >> 1 & 1) + dz_ * (c >> 2 & 1);
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

// The cells whose configuration is non-manifold, by lowest corner, in grid order.
std::vector<std::size_t> non_manifold_cells(const SampledGrid& g) {
  const std::size_t nk = g.num_cells(2);
  std::vector<std::vector<std::size_t>> found(nk);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nk), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k)
      for (std::size_t j = 0; j < g.num_cells(1); ++j)
        for (std::size_t i = 0; i < g.num_cells(0); ++i)
          if (!cell_case(g.cell_mask(i, j, k)).manifold) found[k].push_back(g.index(i, j, k));
  });
  std::vector<std::size_t> cells;
  for (const auto& slab : found) cells.insert(cells.end(), slab.begin(), slab.end());
  return cells;
}

// The non-manifold cells among `cells` and among the cells around the points flipped since
// edit `from`, in grid order: all there are, if `cells` were all before those flips.
std::vector<std::size_t> still_non_manifold(const SampledGrid& g, std::vector<std::size_t> cells,
                                            const RepairCounts& counts, std::size_t from) {
  for (std::size_t e = from; e < counts.edits.size(); ++e)
    for (std::size_t q : cells_around(g, counts.edits[e].point)) cells.push_back(q);
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  std::erase_if(cells, [&](std::size_t c) { return cell_case(g.cell_mask_at(c)).manifold; });
  return cells;
}

// The topology-preserving phase: each non-manifold cell in turn (`cells`, all there are, in
// grid order) gets the best short sequence of simple flips (for marching cubes' (6, 18)
// topology) that lowers the number of non-manifold cells, in rounds until one flips nothing;
// with `deep`, one round of the deep search. That number falls with every sequence, so this
// ends; sequential, in cell order, so it is deterministic. Updates `cells` to the
// non-manifold cells left and returns the number of flips.
enum class Search { short_, prepared, deep };
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

// Moves of one-sample cavities. An outside point whose 18 neighbours are all inside is a
// cavity of its own in marching cubes' (6, 18) topology; it makes a cell non-manifold when it
// touches another outside point through the cell's body diagonal (two cavities, or a cavity
// and the outside, meeting at one point: no conformal mesh with one hex per inside point
// separates them). Every single flip there merges or removes a cavity, but removing it and
// making an identical one nearby keeps the components and the Euler characteristic.
class CavityMove {
 public:
  explicit CavityMove(SampledGrid& g)
      : g_(g), dy_(static_cast<std::ptrdiff_t>(g.padded[0])), dz_(dy_ * static_cast<std::ptrdiff_t>(g.padded[1])) {}

  // For non-manifold `cell`: of its corners that are one-sample cavities, and of the places
  // each could move to, the pair with the lowest |level| sum (ties: the lower indices), which
  // is then applied. Returns false when there is none.
  bool repair(std::size_t cell) {
    bool found = false;
    double best = std::numeric_limits<double>::infinity();
    for (int c = 0; c < 8; ++c) {
      const std::size_t p = cell + static_cast<std::size_t>((c & 1) + dy_ * (c >> 1 & 1) + dz_ * (c >> 2 & 1));
      if (g_.inside[p] || g_.is_padding(p % g_.padded[0], p / g_.padded[0] % g_.padded[1], p / (g_.padded[0] * g_.padded[1])) ||
          !all_inside(p, 2, kNone))
        continue;
      const std::size_t pi = p % g_.padded[0], pj = p / g_.padded[0] % g_.padded[1], pk = p / (g_.padded[0] * g_.padded[1]);
      for (std::ptrdiff_t z = -2; z <= 2; ++z)
        for (std::ptrdiff_t y = -2; y <= 2; ++y)
          for (std::ptrdiff_t x = -2; x <= 2; ++x) {
            // Not padding (and its 26 neighbours within the array).
            if (!inner(pi, x, 0) || !inner(pj, y, 1) || !inner(pk, z, 2) || (x == 0 && y == 0 && z == 0)) continue;
            const std::size_t q = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(p) + x + dy_ * y + dz_ * z);
            if (!g_.inside[q]) continue;
            const double score = std::abs(static_cast<double>(g_.level[p])) + std::abs(static_cast<double>(g_.level[q]));
            if (!(score < best) || !near_surface(g_, q) || !all_inside(q, 3, p)) continue;
            best = score;
            from_ = p;
            to_ = q;
            found = true;
          }
    }
    if (found) {
      g_.inside[from_] = 1;
      g_.inside[to_] = 0;
    }
    return found;
  }
  std::size_t from() const { return from_; }
  std::size_t to() const { return to_; }

 private:
  static constexpr std::size_t kNone = ~std::size_t{0};

  // Padded coordinate v + d of axis a is at least 1 and at most padded[a] - 2.
  bool inner(std::size_t v, std::ptrdiff_t d, int a) const {
    const std::ptrdiff_t w = static_cast<std::ptrdiff_t>(v) + d;
    return w >= 1 && w + 2 <= static_cast<std::ptrdiff_t>(g_.padded[a]);
  }

  // Every neighbour of p within `reach` (2: the 18-neighbourhood, 3: the 26-) is inside, or
  // is `also` (a point about to be made inside).
  bool all_inside(std::size_t p, int reach, std::size_t also) const {
    for (std::ptrdiff_t z = -1; z <= 1; ++z)
      for (std::ptrdiff_t y = -1; y <= 1; ++y)
        for (std::ptrdiff_t x = -1; x <= 1; ++x) {
          const int d = (x != 0) + (y != 0) + (z != 0);
          if (d == 0 || d > reach) continue;
          const std::size_t q = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(p) + x + dy_ * y + dz_ * z);
          if (!g_.inside[q] && q != also) return false;
        }
    return true;
  }

  SampledGrid& g_;
  std::ptrdiff_t dy_, dz_;
  std::size_t from_ = 0, to_ = 0;
};

// Each non-manifold cell in grid order gets a move of two flips (`move(cell, a, b)`: a cavity
// move or a tunnel move) if it has one; sequential, so it is deterministic. Returns the moves.
template <typename Move>
std::size_t relocation_phase(SampledGrid& g, RepairCounts& counts, std::vector<std::size_t>& cells, Move&& move) {
  ++counts.rounds;
  std::size_t moves = 0;
  const std::size_t from = counts.edits.size();
  for (std::size_t cell : cells) {
    std::size_t a = 0, b = 0;
    if (cell_case(g.cell_mask_at(cell)).manifold || !move(cell, a, b)) continue;
    for (std::size_t p : {a, b}) {
      counts.edits.push_back({p, RepairKind::relocated});
      ++(g.inside[p] ? counts.filled : counts.carved);
    }
    counts.relocated += 2;
    ++moves;
  }
  cells = still_non_manifold(g, std::move(cells), counts, from);
  return moves;
}

}  // namespace

std::size_t fill_degenerate_cavities(SampledGrid& g, RepairCounts& counts) {
  const std::size_t dy = g.padded[0], dz = g.padded[0] * g.padded[1];
  // Candidates: outside samples at L == 0 exactly, gathered per slab in parallel, in grid order.
  std::vector<std::vector<std::size_t>> found(g.padded[2]);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(1, g.padded[2] - 1), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k)
      for (std::size_t p = dz * k + dy, end = dz * (k + 1) - dy; p < end; ++p)
        if (!g.inside[p] && g.on_isosurface(p)) found[k].push_back(p);
  });
  std::vector<std::size_t> seeds;
  for (const auto& slab : found) seeds.insert(seeds.end(), slab.begin(), slab.end());
  if (seeds.empty()) return 0;
  // The 18-neighbourhood: offsets with one or two nonzero coordinates.
  std::vector<std::ptrdiff_t> nb;
  for (int z = -1; z <= 1; ++z)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x) {
        const int d = (x != 0) + (y != 0) + (z != 0);
        if (d == 1 || d == 2)
          nb.push_back(x + static_cast<std::ptrdiff_t>(dy) * y + static_cast<std::ptrdiff_t>(dz) * z);
      }
  auto zero_outside = [&](std::size_t p) { return !g.inside[p] && g.on_isosurface(p); };
  std::vector<std::uint8_t> seen(g.inside.size(), 0);
  std::vector<std::size_t> part, stack;
  std::size_t cavities = 0;
  for (std::size_t seed : seeds) {
    if (seen[seed]) continue;
    // The outside part through `seed`, walked through its samples at L == 0; it is a
    // candidate while it meets no other outside sample (L < 0, NaN or padding).
    bool zero = true;
    part.assign(1, seed);
    stack.assign(1, seed);
    seen[seed] = 1;
    while (!stack.empty()) {
      const std::size_t p = stack.back();
      stack.pop_back();
      for (std::ptrdiff_t d : nb) {  // p is not padding, so its neighbours are in the array
        const std::size_t q = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(p) + d);
        if (g.inside[q]) continue;
        if (!g.on_isosurface(q)) {
          zero = false;
          continue;
        }
        if (seen[q]) continue;
        seen[q] = 1;
        part.push_back(q);
        stack.push_back(q);
      }
    }
    if (!zero) continue;
    // Zero volume: no cell has all 8 corners in the part (L == 0 throughout such a cell).
    bool flat = true;
    for (std::size_t p : part) {
      bool whole = true;
      for (int c = 0; c < 8 && whole; ++c) whole = zero_outside(p + (c & 1) + dy * (c >> 1 & 1) + dz * (c >> 2 & 1));
      if (whole) {
        flat = false;
        break;
      }
    }
    if (!flat) continue;
    std::sort(part.begin(), part.end());
    for (std::size_t p : part) {
      g.inside[p] = 1;
      counts.edits.push_back({p, RepairKind::degenerate});
    }
    counts.filled += part.size();
    counts.degenerate += part.size();
    ++cavities;
  }
  counts.degenerate_components += cavities;
  return cavities;
}

RepairCounts repair_manifold(SampledGrid& g) {
  RepairCounts counts;
  fill_degenerate_cavities(g, counts);
  const std::size_t dz = g.padded[0] * g.padded[1];
  std::vector<std::size_t> cells = non_manifold_cells(g);
  simple_phase(g, counts, Search::short_, cells);
  // Where no short sequence exists: cavity moves, prepared sequences, the deep search, the
  // first that does anything; then short sequences again around what changed.
  while (!cells.empty()) {
    CavityMove cavity(g);
    auto move_cavity = [&](std::size_t cell, std::size_t& a, std::size_t& b) {
      return cavity.repair(cell) && (a = cavity.from(), b = cavity.to(), true);
    };
    auto tunnel = [&](std::size_t cell, std::size_t& a, std::size_t& b) { return move_tunnel(g, cell, a, b); };
    if (relocation_phase(g, counts, cells, move_cavity) == 0 && simple_phase(g, counts, Search::prepared, cells) == 0 &&
        simple_phase(g, counts, Search::deep, cells) == 0 && relocation_phase(g, counts, cells, tunnel) == 0)
      break;
    simple_phase(g, counts, Search::short_, cells);
  }
  const std::size_t simple_carved = counts.carved, simple_filled = counts.filled;
  const std::size_t before_carving = counts.edits.size();
  counts.carved = repair_phase(g, 0, cells, counts, [&](std::uint8_t m, std::size_t i, std::size_t j, std::size_t k) {
    const std::uint8_t cand = carve_candidates(m);
    if (!cand) return std::uint8_t{0};
    float level[8];
    std::uint8_t allowed = 0;
    const std::size_t base = g.index(i, j, k);
    for (int c = 0; c < 8; ++c) {
      const std::size_t p = base + static_cast<std::size_t>(c & 1) + g.padded[0] * static_cast<std::size_t>(c >> 1 & 1) +
                            dz * static_cast<std::size_t>(c >> 2 & 1);
      level[c] = g.level[p];
      if ((cand >> c & 1) && carving_keeps_inside_connected(g, p)) allowed |= static_cast<std::uint8_t>(1u << c);
    }
    return manifold_carve(m, level, allowed);
  });
  cells = still_non_manifold(g, std::move(cells), counts, before_carving);
  counts.filled = repair_phase(g, 1, cells, counts, [&](std::uint8_t m, std::size_t i, std::size_t j, std::size_t k) {
    return manifold_fill(m, g.padding_mask(i, j, k));
  });
  counts.forced = counts.carved + counts.filled;
  counts.carved += simple_carved;
  counts.filled += simple_filled;
  return counts;
}

ComponentCounts remove_small_components(SampledGrid& g, std::size_t min_points) {
  ComponentCounts counts;
  // Sequential flood fill: labels depend only on the grid, and it is cheap next to sampling.
  std::vector<std::int32_t> label(g.inside.size(), -1);
  std::vector<std::size_t> sizes, stack;
  const std::size_t steps[3] = {1, g.padded[0], g.padded[0] * g.padded[1]};
  for (std::size_t seed = 0; seed < g.inside.size(); ++seed) {
    if (!g.inside[seed] || label[seed] >= 0) continue;
    const auto id = static_cast<std::int32_t>(sizes.size());
    std::size_t n = 0;
    label[seed] = id;
    stack.push_back(seed);
    while (!stack.empty()) {
      const std::size_t p = stack.back();
      stack.pop_back();
      ++n;
      // Inside points are never padding, so p ± step stays in the array.
      for (std::size_t s : steps)
        for (std::size_t q : {p - s, p + s})
          if (g.inside[q] && label[q] < 0) {
            label[q] = id;
            stack.push_back(q);
          }
    }
    sizes.push_back(n);
  }
  for (std::size_t n : sizes) {
    if (n < min_points) {
      ++counts.removed;
      counts.removed_points += n;
    } else {
      ++counts.kept;
    }
  }
  if (counts.removed)
    for (std::size_t p = 0; p < g.inside.size(); ++p)
      if (g.inside[p] && sizes[static_cast<std::size_t>(label[p])] < min_points) g.inside[p] = 0;
  return counts;
}

}  // namespace isohex::contour
