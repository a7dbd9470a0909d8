// Dual sheets: counts on grids, self-intersection, boundary capture before and after pillowing.
#include "isohex/error.hpp"
#include "isohex/mesh/generate.hpp"
#include "isohex/sheets/dual_sheets.hpp"
#include "isohex/sheets/pillow.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace isohex::test {
namespace {

TEST(DualSheets, BoxGridHasOneSheetPerLayer) {
  const HexMesh m = grid_mesh(2, 3, 4);
  const SheetReport r = extract_sheets(m);
  EXPECT_EQ(r.num_sheets, 2u + 3u + 4u);
  std::vector<std::size_t> sizes = r.sheet_sizes;
  std::sort(sizes.begin(), sizes.end());
  // x layers hold 3×4 hexes, y layers 2×4, z layers 2×3.
  EXPECT_EQ(sizes, (std::vector<std::size_t>{6, 6, 6, 6, 8, 8, 8, 12, 12}));
  EXPECT_TRUE(r.self_intersecting.empty());
  ASSERT_EQ(r.boundary_capture.size(), 1u);
  EXPECT_EQ(r.boundary_capture[0].size(), 6u);  // the two outer layers in each direction
  EXPECT_EQ(r.boundary_component_quads[0], 2u * (6 + 8 + 12));
  EXPECT_EQ(r.multi_boundary_hexes, 20u);  // all but the 4 hexes in the middle of both y and z
}

TEST(DualSheets, BoundaryPillowingCapturesEachComponentWithOneNewSheet) {
  HexMesh cavity = grid_mesh(5, 5, 5);
  cavity.hexes.erase(cavity.hexes.begin() + (2 + 5 * (2 + 5 * 2)));
  for (const HexMesh& m : {grid_mesh(3, 4, 5), cavity, ball_mesh(5)}) {
    const SheetReport before = extract_sheets(m);
    const PillowResult p = pillow_boundary(m);
    const SheetReport after = extract_sheets(p.mesh);
    const std::size_t components = before.boundary_capture.size();
    EXPECT_EQ(after.boundary_capture.size(), components);
    EXPECT_EQ(after.num_sheets, before.num_sheets + components);
    std::vector<Index> capturing;
    for (const auto& sheets : after.boundary_capture) {
      ASSERT_EQ(sheets.size(), 1u);
      capturing.push_back(sheets[0]);
      // The new sheet consists of exactly the new hexes of that component.
      EXPECT_EQ(after.sheet_sizes[sheets[0]],
                after.boundary_component_quads[&sheets - after.boundary_capture.data()]);
    }
    std::sort(capturing.begin(), capturing.end());
    EXPECT_EQ(std::unique(capturing.begin(), capturing.end()), capturing.end());
    EXPECT_GT(before.multi_boundary_hexes, 0u);
    EXPECT_EQ(after.multi_boundary_hexes, 0u);
    EXPECT_EQ(after.self_intersecting.size(), before.self_intersecting.size());
  }
}

/// A ring of n hexes; with `twist` the last hex is glued to the first turned by a quarter,
/// which merges the ring's two transverse sheets into one that meets itself in every hex.
HexMesh ring(int n, bool twist) {
  HexMesh m;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * std::numbers::pi * k / n;
    const Vec3 c(3 * std::cos(a), 3 * std::sin(a), 0), r(std::cos(a), std::sin(a), 0), z(0, 0, 1);
    for (const auto& [s, t] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) m.points.push_back(c + 0.5 * (s * r + t * z));
  }
  for (int k = 0; k < n; ++k) {
    const int a = 4 * k, b = 4 * ((k + 1) % n);
    const int shift = twist && k == n - 1 ? 1 : 0;
    m.hexes.push_back({a, a + 1, a + 2, a + 3, b + shift % 4, b + (1 + shift) % 4, b + (2 + shift) % 4,
                       b + (3 + shift) % 4});
  }
  return m;
}

TEST(DualSheets, TwistedRingSheetMeetsItself) {
  const SheetReport plain = extract_sheets(ring(8, false));
  EXPECT_EQ(plain.num_sheets, 8u + 2u);  // one per hex across the ring, two around it
  EXPECT_TRUE(plain.self_intersecting.empty());
  const SheetReport twisted = extract_sheets(ring(8, true));
  EXPECT_EQ(twisted.num_sheets, 8u + 1u);
  ASSERT_EQ(twisted.self_intersecting.size(), 1u);
  EXPECT_EQ(twisted.self_intersecting_hexes, 8u);
  EXPECT_EQ(twisted.sheet_sizes[twisted.self_intersecting[0]], 8u);
}

TEST(DualSheets, OutOfRangeIdsAreAnError) {
  HexMesh m = grid_mesh(1, 1, 1);
  m.hexes[0][3] = 42;
  EXPECT_THROW(extract_sheets(m), Error);
}

}  // namespace
}  // namespace isohex::test
