#include "isohex/contour/simple_point.hpp"

#include <cstdint>
#include <cstdlib>

namespace isohex::contour {

namespace {

constexpr int kCentre = 13;

// Number of coordinates in which positions a and b of the block differ (each by at most 1,
// or more: then they are not neighbours at all).
int distance_class(int a, int b) {
  const int dx = std::abs(a % 3 - b % 3), dy = std::abs(a / 3 % 3 - b / 3 % 3), dz = std::abs(a / 9 - b / 9);
  if (dx > 1 || dy > 1 || dz > 1) return 4;
  return dx + dy + dz;
}

// Adjacency as the largest number of differing coordinates: 1 for 6-, 2 for 18-, 3 for 26-.
bool adjacent(int a, int b, int reach) {
  const int d = distance_class(a, b);
  return d >= 1 && d <= reach;
}

// Bertrand & Malandain's geodesic neighbourhood N_reach^order(x, set) within the
// 26-neighbourhood, as a bit set of block positions.
std::uint32_t geodesic(std::uint32_t set, int reach, int order) {
  std::uint32_t g = 0;
  for (int p = 0; p < 27; ++p)
    if ((set >> p & 1u) && adjacent(p, kCentre, reach)) g |= 1u << p;
  for (int step = 1; step < order; ++step) {
    std::uint32_t next = g;
    for (int p = 0; p < 27; ++p) {
      if (!(set >> p & 1u) || (g >> p & 1u)) continue;
      for (int q = 0; q < 27; ++q)
        if ((g >> q & 1u) && adjacent(p, q, reach)) {
          next |= 1u << p;
          break;
        }
    }
    g = next;
  }
  return g;
}

// Number of components of `set` under the adjacency of `reach`.
int components(std::uint32_t set, int reach) {
  int n = 0;
  while (set) {
    ++n;
    std::uint32_t part = set & (~set + 1), frontier = part;  // lowest position
    while (frontier) {
      std::uint32_t next = 0;
      for (int p = 0; p < 27; ++p) {
        if (!(set >> p & 1u) || (part >> p & 1u)) continue;
        for (int q = 0; q < 27; ++q)
          if ((frontier >> q & 1u) && adjacent(p, q, reach)) {
            next |= 1u << p;
            break;
          }
      }
      part |= next;
      frontier = next;
    }
    set &= ~part;
  }
  return n;
}

}  // namespace

std::array<int, 2> topological_numbers_6_18(const Neighbourhood& nb) {
  std::uint32_t in = 0, out = 0;
  for (int p = 0; p < 27; ++p) {
    if (p == kCentre) continue;
    (nb[static_cast<std::size_t>(p)] ? in : out) |= 1u << p;
  }
  // T6+(x, X) = #C6(N6^3(x, X)), T18(x, X̄) = #C18(N18^2(x, X̄)).
  return {components(geodesic(in, 1, 3), 1), components(geodesic(out, 2, 2), 2)};
}

bool is_simple_6_18(const Neighbourhood& nb) { return topological_numbers_6_18(nb) == std::array<int, 2>{1, 1}; }

}  // namespace isohex::contour
