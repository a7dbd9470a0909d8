#include "isohex/contour/handle_move.hpp"

#include "isohex/contour/cell_cases.hpp"
#include "isohex/contour/simple_point.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace isohex::contour {

namespace {

constexpr int kReach = 4;  // half-width of the box the connectivity checks look in
constexpr int kBox = 2 * kReach + 1;

struct Local {
  const SampledGrid& g;
  std::ptrdiff_t dy, dz;
  std::ptrdiff_t at(std::size_t p, int x, int y, int z) const { return static_cast<std::ptrdiff_t>(p) + x + dy * y + dz * z; }

  std::array<int, 2> numbers(std::size_t p) const {
    Neighbourhood nb{};
    for (int z = 0; z < 3; ++z)
      for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 3; ++x)
          nb[static_cast<std::size_t>(x + 3 * y + 9 * z)] = g.inside[static_cast<std::size_t>(at(p, x - 1, y - 1, z - 1))] != 0;
    return topological_numbers_6_18(nb);
  }

  // True when the 26-neighbours of p in state `state` that are within `reach` of it (1: the
  // 6-neighbours, 2: the 18-) are all connected to one another, under that adjacency, by points
  // of that state in the box of kReach around p, p excluded (the box clipped to the grid).
  bool joined_in_box(std::size_t p, std::uint8_t state, int reach) const {
    const std::ptrdiff_t pi = static_cast<std::ptrdiff_t>(p % g.padded[0]), pj = static_cast<std::ptrdiff_t>(p / g.padded[0] % g.padded[1]),
                         pk = static_cast<std::ptrdiff_t>(p / (g.padded[0] * g.padded[1]));
    auto in_box = [&](int x, int y, int z) {
      return std::abs(x) <= kReach && std::abs(y) <= kReach && std::abs(z) <= kReach && pi + x >= 0 && pj + y >= 0 && pk + z >= 0 &&
             pi + x < static_cast<std::ptrdiff_t>(g.padded[0]) && pj + y < static_cast<std::ptrdiff_t>(g.padded[1]) &&
             pk + z < static_cast<std::ptrdiff_t>(g.padded[2]);
    };
    auto of = [&](int x, int y, int z) { return (x + kReach) + kBox * ((y + kReach) + kBox * (z + kReach)); };
    auto ok = [&](int x, int y, int z) {
      return in_box(x, y, z) && (x || y || z) && g.inside[static_cast<std::size_t>(at(p, x, y, z))] == state;
    };
    std::vector<std::uint8_t> seen(kBox * kBox * kBox, 0);
    std::vector<std::array<int, 3>> stack;
    int targets = 0, reached = 0;
    for (int z = -1; z <= 1; ++z)
      for (int y = -1; y <= 1; ++y)
        for (int x = -1; x <= 1; ++x) {
          const int d = (x != 0) + (y != 0) + (z != 0);
          if (d == 0 || d > reach || !ok(x, y, z)) continue;
          ++targets;
          if (stack.empty()) {
            stack.push_back({x, y, z});
            seen[static_cast<std::size_t>(of(x, y, z))] = 1;
          }
        }
    while (!stack.empty()) {
      const auto [x, y, z] = stack.back();
      stack.pop_back();
      if (std::max({std::abs(x), std::abs(y), std::abs(z)}) <= 1 && (x != 0) + (y != 0) + (z != 0) <= reach) ++reached;
      for (int c = -1; c <= 1; ++c)
        for (int b = -1; b <= 1; ++b)
          for (int a = -1; a <= 1; ++a) {
            const int d = (a != 0) + (b != 0) + (c != 0);
            if (d == 0 || d > reach || !ok(x + a, y + b, z + c)) continue;
            std::uint8_t& s = seen[static_cast<std::size_t>(of(x + a, y + b, z + c))];
            if (s) continue;
            s = 1;
            stack.push_back({x + a, y + b, z + c});
          }
    }
    return reached == targets;
  }

  // The change of genus flipping p makes: -1 when it closes a tunnel (an outside point with
  // numbers {1, 2}) or cuts a handle (an inside point with {2, 1}), +1 when it makes one (an
  // outside point with {2, 1}, an inside point with {1, 2}), in each case only when the two
  // local parts it joins or separates are joined within the box (else it would merge or split
  // a component, or make or fill a cavity); 0 otherwise (simple, or not known).
  int genus_change(std::size_t p) const {
    const std::array<int, 2> t = numbers(p);
    const bool in = g.inside[p] != 0;
    if (t == std::array<int, 2>{1, 2}) return joined_in_box(p, 0, 2) ? (in ? 1 : -1) : 0;
    if (t == std::array<int, 2>{2, 1}) return joined_in_box(p, 1, 1) ? (in ? -1 : 1) : 0;
    return 0;
  }

  int non_manifold(std::size_t x, std::size_t y) const {
    std::array<std::size_t, 16> cells{};
    for (int c = 0; c < 8; ++c) {
      cells[static_cast<std::size_t>(c)] = static_cast<std::size_t>(at(x, -(c & 1), -(c >> 1 & 1), -(c >> 2 & 1)));
      cells[static_cast<std::size_t>(c + 8)] = static_cast<std::size_t>(at(y, -(c & 1), -(c >> 1 & 1), -(c >> 2 & 1)));
    }
    std::sort(cells.begin(), cells.end());
    int n = 0;
    for (std::size_t i = 0; i < cells.size(); ++i)
      if ((i == 0 || cells[i] != cells[i - 1]) && !cell_case(g.cell_mask_at(cells[i])).manifold) ++n;
    return n;
  }
};

}  // namespace

bool move_tunnel(SampledGrid& g, std::size_t cell, std::size_t& first, std::size_t& second) {
  const Local l{g, static_cast<std::ptrdiff_t>(g.padded[0]), static_cast<std::ptrdiff_t>(g.padded[0] * g.padded[1])};
  int best_n = std::numeric_limits<int>::max();
  double best_score = std::numeric_limits<double>::infinity();
  bool found = false;
  for (int c = 0; c < 8; ++c) {
    const std::size_t x = static_cast<std::size_t>(l.at(cell, c & 1, c >> 1 & 1, c >> 2 & 1));
    if (!near_surface(g, x)) continue;
    const int dx = l.genus_change(x);
    if (dx == 0) continue;
    const auto xi = static_cast<std::ptrdiff_t>(x % g.padded[0]), xj = static_cast<std::ptrdiff_t>(x / g.padded[0] % g.padded[1]),
               xk = static_cast<std::ptrdiff_t>(x / (g.padded[0] * g.padded[1]));
    for (int z = -2; z <= 2; ++z)
      for (int y = -2; y <= 2; ++y)
        for (int w = -2; w <= 2; ++w) {
          // Within the grid with its 26 neighbours (near_surface rejects padding).
          if (xi + w < 1 || xj + y < 1 || xk + z < 1 || xi + w + 1 >= static_cast<std::ptrdiff_t>(g.padded[0]) ||
              xj + y + 1 >= static_cast<std::ptrdiff_t>(g.padded[1]) || xk + z + 1 >= static_cast<std::ptrdiff_t>(g.padded[2]))
            continue;
          const std::size_t q = static_cast<std::size_t>(l.at(x, w, y, z));
          if (q == x || !near_surface(g, q)) continue;
          const double score = std::abs(static_cast<double>(g.level[x])) + std::abs(static_cast<double>(g.level[q]));
          if (!(score < best_score) && best_n == 0) continue;
          const int before = l.non_manifold(x, q);
          g.inside[x] ^= 1;
          if (l.genus_change(q) == -dx) {
            g.inside[q] ^= 1;
            const int after = l.non_manifold(x, q);
            if (after < before && (after < best_n || (after == best_n && score < best_score))) {
              best_n = after;
              best_score = score;
              first = x;
              second = q;
              found = true;
            }
            g.inside[q] ^= 1;
          }
          g.inside[x] ^= 1;
        }
  }
  if (found) {
    g.inside[first] ^= 1;
    g.inside[second] ^= 1;
  }
  return found;
}

}  // namespace isohex::contour
