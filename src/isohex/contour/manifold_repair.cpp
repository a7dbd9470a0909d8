// The manifold repair (repair_manifold): the order of its phases, the cavity moves, the
// relocation phase (cavity and tunnel moves) and the forced edits; the simple-flip searches are
// in flip_search.cpp, the tunnel moves in handle_move.cpp.
#include "isohex/contour/cell_cases.hpp"
#include "isohex/contour/handle_move.hpp"
#include "isohex/contour/repair_internal.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace isohex::contour {

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

}  // namespace

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

namespace {

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
      const std::size_t p = g_.corner_at(cell, c);
      // A cavity at L == 0 has no volume: it is filled (fill_degenerate_cavities), not moved
      // to a sample inside the field, whose cavity no surface bounds.
      if (g_.inside[p] || g_.on_isosurface(p) ||
          g_.is_padding(p % g_.padded[0], p / g_.padded[0] % g_.padded[1], p / (g_.padded[0] * g_.padded[1])) ||
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

RepairCounts repair_manifold(SampledGrid& g) {
  RepairCounts counts;
  fill_degenerate_cavities(g, counts);
  fill_zero_level_samples(g, counts);
  std::vector<std::size_t> cells = non_manifold_cells(g);
  simple_phase(g, counts, Search::short_, cells);
  // Where no short sequence exists: cavity moves, prepared sequences, the deep search, the
  // first that does anything; then short sequences again around what changed.
  while (!cells.empty()) {
    // The simple flips can enclose a sample at L == 0 as a cavity of its own.
    const std::size_t before_fill = counts.edits.size();
    if (fill_degenerate_cavities(g, counts) > 0) cells = still_non_manifold(g, std::move(cells), counts, before_fill);
    if (cells.empty()) break;
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
  const std::size_t before_zero = counts.edits.size();
  fill_zero_level_samples(g, counts);
  cells = still_non_manifold(g, std::move(cells), counts, before_zero);
  const std::size_t simple_carved = counts.carved;
  std::size_t simple_filled = counts.filled;
  const std::size_t before_carving = counts.edits.size();
  counts.carved = repair_phase(g, 0, cells, counts, [&](std::uint8_t m, std::size_t i, std::size_t j, std::size_t k) {
    const std::uint8_t cand = carve_candidates(m);
    if (!cand) return std::uint8_t{0};
    float level[8];
    std::uint8_t allowed = 0;
    const std::size_t base = g.index(i, j, k);
    for (int c = 0; c < 8; ++c) {
      const std::size_t p = g.corner_at(base, c);
      level[c] = g.level[p];
      if ((cand >> c & 1) && carving_keeps_inside_connected(g, p)) allowed |= static_cast<std::uint8_t>(1u << c);
    }
    return manifold_carve(m, level, allowed);
  });
  cells = still_non_manifold(g, std::move(cells), counts, before_carving);
  auto fill = [&](std::uint8_t m, std::size_t i, std::size_t j, std::size_t k) {
    return manifold_fill(m, g.padding_mask(i, j, k));
  };
  counts.filled = repair_phase(g, 1, cells, counts, fill);
  // Samples at L == 0 that still pin several cells' dual vertices are filled anyway, and what
  // that makes non-manifold is filled too; fills only, so this ends.
  for (std::size_t from = counts.edits.size(); fill_shared_pins(g, counts) > 0; from = counts.edits.size()) {
    simple_filled += counts.edits.size() - from;
    counts.filled += repair_phase(g, 1, still_non_manifold(g, {}, counts, from), counts, fill);
  }
  counts.forced = counts.carved + counts.filled;
  counts.carved += simple_carved;
  counts.filled += simple_filled;
  return counts;
}

}  // namespace isohex::contour
