#include "isohex/contour/cell_cases.hpp"

#include <bit>

namespace isohex::contour {

namespace {

// Corners adjacent to corner c: flip one coordinate bit.
constexpr std::uint8_t neighbours(int c) {
  return static_cast<std::uint8_t>((1u << (c ^ 1)) | (1u << (c ^ 2)) | (1u << (c ^ 4)));
}

// The part of `set` connected to corner `seed` (which must be in `set`).
std::uint8_t flood(std::uint8_t set, int seed) {
  std::uint8_t part = static_cast<std::uint8_t>(1u << seed), frontier = part;
  while (frontier) {
    std::uint8_t next = 0;
    for (int c = 0; c < 8; ++c)
      if (frontier & (1u << c)) next |= neighbours(c);
    next &= static_cast<std::uint8_t>(set & ~part);
    part |= next;
    frontier = next;
  }
  return part;
}

// Splits `set` into its connected parts, in order of their lowest corner.
int parts_of(std::uint8_t set, std::array<std::uint8_t, 8>& parts) {
  int n = 0;
  while (set) {
    parts[n] = flood(set, std::countr_zero(set));
    set &= static_cast<std::uint8_t>(~parts[n]);
    ++n;
  }
  return n;
}

struct Table {
  std::array<CellCase, 256> cases;
  Table() {
    for (int m = 0; m < 256; ++m) {
      CellCase& cc = cases[m];
      cc.component.fill(-1);
      std::array<std::uint8_t, 8> comps{};
      cc.num_components = static_cast<std::uint8_t>(parts_of(static_cast<std::uint8_t>(m), comps));
      for (int k = 0; k < cc.num_components; ++k) {
        for (int c = 0; c < 8; ++c)
          if (comps[k] & (1u << c)) cc.component[c] = static_cast<std::int8_t>(k);
        std::array<std::uint8_t, 8> rest{};
        if (parts_of(static_cast<std::uint8_t>(~comps[k]), rest) > 1) cc.manifold = false;
      }
    }
  }
};

const Table& table() {
  static const Table t;
  return t;
}

}  // namespace

const CellCase& cell_case(std::uint8_t mask) { return table().cases[mask]; }

std::uint8_t manifold_fill(std::uint8_t mask, std::uint8_t fixed_outside) {
  if (cell_case(mask).manifold) return 0;
  std::array<std::uint8_t, 8> comps{};
  const int n = parts_of(mask, comps);
  std::uint8_t fill = 0;
  for (int k = 0; k < n; ++k) {
    std::array<std::uint8_t, 8> rest{};
    const int r = parts_of(static_cast<std::uint8_t>(~comps[k]), rest);
    if (r < 2) continue;
    int keep = 0;
    for (int i = 0; i < r; ++i) {
      if (rest[i] & fixed_outside) {
        keep = i;
        break;
      }
      if (std::popcount(rest[i]) > std::popcount(rest[keep])) keep = i;
    }
    for (int i = 0; i < r; ++i)
      if (i != keep) fill |= static_cast<std::uint8_t>(rest[i] & ~mask);
  }
  return static_cast<std::uint8_t>(fill & ~fixed_outside);
}

namespace {

// Calls f(a, b) for each pair of corners in different parts of a non-manifold component's
// complement that lie on a common face diagonal.
template <typename F>
void for_edge_contacts(std::uint8_t mask, F&& f) {
  std::array<std::uint8_t, 8> comps{};
  const int n = parts_of(mask, comps);
  for (int k = 0; k < n; ++k) {
    std::array<std::uint8_t, 8> rest{};
    const int r = parts_of(static_cast<std::uint8_t>(~comps[k]), rest);
    for (int x = 0; x < r; ++x)
      for (int y = x + 1; y < r; ++y)
        for (int a = 0; a < 8; ++a)
          for (int b = 0; b < 8; ++b)
            if ((rest[x] >> a & 1) && (rest[y] >> b & 1) && std::popcount(static_cast<unsigned>(a ^ b)) == 2) f(a, b);
  }
}

}  // namespace

bool has_edge_contact(std::uint8_t mask) {
  if (cell_case(mask).manifold) return false;
  bool found = false;
  for_edge_contacts(mask, [&](int, int) { found = true; });
  return found;
}

std::uint8_t carve_candidates(std::uint8_t mask) {
  if (cell_case(mask).manifold) return 0;
  std::uint8_t out = 0;
  for_edge_contacts(mask, [&](int a, int b) {
    // The face's other diagonal: both corners are inside (an outside one would join a and b).
    const int d = a ^ b;
    out |= static_cast<std::uint8_t>(1u << (a ^ (d & -d)) | 1u << (a ^ (d & (d - 1))));
  });
  return static_cast<std::uint8_t>(out & mask);
}

std::uint8_t manifold_carve(std::uint8_t mask, const float level[8], std::uint8_t allowed) {
  const std::uint8_t cand = static_cast<std::uint8_t>(carve_candidates(mask) & allowed);
  int best = -1;
  for (int c = 0; c < 8; ++c)
    if ((cand >> c & 1) && (best < 0 || level[c] < level[best])) best = c;
  return best < 0 ? std::uint8_t{0} : static_cast<std::uint8_t>(1u << best);
}

}  // namespace isohex::contour
