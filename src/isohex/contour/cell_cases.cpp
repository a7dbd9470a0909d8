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

}  // namespace isohex::contour
