// Small enclosed voids (cavities of the region): fill_small_cavities on a constructed grid, and
// through the mesher (ExtractOptions::min_cavity) on a voxel block with two voids.
#include "isohex/contour/dual_contour.hpp"
#include "isohex/contour/sampled_grid.hpp"
#include "isohex/mesh/validate.hpp"

#include <gtest/gtest.h>

#include <array>
#include <vector>

namespace isohex::contour {
namespace {

// A padded grid of n^3 points, every non-padding point inside except `outside`.
SampledGrid grid_with_outside(std::size_t n, const std::vector<std::array<std::size_t, 3>>& outside) {
  SampledGrid g;
  g.padded = {n, n, n};
  g.inside.assign(n * n * n, 0);
  g.level.assign(n * n * n, 1.0f);
  for (std::size_t k = 1; k + 1 < n; ++k)
    for (std::size_t j = 1; j + 1 < n; ++j)
      for (std::size_t i = 1; i + 1 < n; ++i) g.inside[g.index(i, j, k)] = 1;
  for (const auto& p : outside) g.inside[g.index(p[0], p[1], p[2])] = 0;
  return g;
}

// Outside points meet across edges and corners (26-adjacency): (4,4,4) and (5,5,5) are one
// cavity of two points; (2,2,2) reaches the open outside through (1,1,1), which touches the
// padding, so it is never filled however small.
TEST(ContourCavities, TwentySixConnectedPartsThatMissThePaddingAreFilledBelowTheMinimum) {
  const std::vector<std::array<std::size_t, 3>> outside = {{1, 1, 1}, {2, 2, 2}, {4, 4, 4}, {5, 5, 5}};
  SampledGrid kept = grid_with_outside(8, outside);
  const CavityCounts k = fill_small_cavities(kept, 2);
  EXPECT_EQ(k.filled, 0u);
  EXPECT_EQ(k.kept, 1u);
  for (const auto& p : outside) EXPECT_FALSE(kept.inside[kept.index(p[0], p[1], p[2])]);

  SampledGrid filled = grid_with_outside(8, outside);
  const CavityCounts f = fill_small_cavities(filled, 3);
  EXPECT_EQ(f.filled, 1u);
  EXPECT_EQ(f.filled_points, 2u);
  EXPECT_EQ(f.kept, 0u);
  EXPECT_TRUE(filled.inside[filled.index(4, 4, 4)]);
  EXPECT_TRUE(filled.inside[filled.index(5, 5, 5)]);
  EXPECT_FALSE(filled.inside[filled.index(1, 1, 1)]);
  EXPECT_FALSE(filled.inside[filled.index(2, 2, 2)]);
  // Nothing else changed: every other point as before.
  SampledGrid before = grid_with_outside(8, outside);
  std::size_t changed = 0;
  for (std::size_t p = 0; p < before.inside.size(); ++p) changed += before.inside[p] != filled.inside[p];
  EXPECT_EQ(changed, 2u);
}

// A 10^3 block of samples with a one-sample void and a 3x3x3 void: min_cavity 8 fills the
// first (its 6 boundary quads go) and keeps the second; 0 keeps both. Both meshes are valid
// with closed manifold boundaries.
TEST(ContourCavities, TheMesherFillsOnlyTheVoidsBelowTheMinimum) {
  Volume v;
  v.dims = {14, 14, 14};
  v.values.assign(v.size(), 0.0f);
  for (Index z = 2; z < 12; ++z)
    for (Index y = 2; y < 12; ++y)
      for (Index x = 2; x < 12; ++x) v.at(x, y, z) = 1.0f;
  v.at(4, 4, 4) = 0.0f;
  for (Index z = 7; z < 10; ++z)
    for (Index y = 7; y < 10; ++y)
      for (Index x = 7; x < 10; ++x) v.at(x, y, z) = 0.0f;
  RegionSpec spec;
  spec.isovalue = 0.5;
  const Region region = make_region(v, spec);
  ExtractOptions opt;
  opt.cell_size = 1;
  const ExtractResult all = extract_hex_mesh(region, opt);
  opt.min_cavity = 8;
  const ExtractResult some = extract_hex_mesh(region, opt);
  EXPECT_EQ(all.report.filled_cavities, 0u);
  EXPECT_EQ(some.report.filled_cavities, 1u);
  EXPECT_EQ(some.report.filled_cavity_points, 1u);
  EXPECT_EQ(some.report.kept_cavities, 1u);
  EXPECT_EQ(some.mesh.num_hexes(), all.mesh.num_hexes() + 1);
  const ValidationReport ca = validate(all.mesh), cs = validate(some.mesh);
  EXPECT_TRUE(ca.valid());
  EXPECT_TRUE(cs.valid());
  EXPECT_EQ(ca.num_boundary_components, 3u);
  EXPECT_EQ(cs.num_boundary_components, 2u);
  EXPECT_EQ(ca.num_boundary_quads, cs.num_boundary_quads + 6);
}

}  // namespace
}  // namespace isohex::contour
