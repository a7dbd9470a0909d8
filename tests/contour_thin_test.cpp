// Filaments far thinner than a cell (carve_thin_features): carved from their tips, the rest of
// the solid kept sample for sample, and nothing carved that is thick, a sheet, or a closed loop.
#include "isohex/contour/dual_contour.hpp"
#include "isohex/contour/sampled_grid.hpp"
#include "isohex/mesh/validate.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <array>
#include <vector>

namespace isohex::contour {
namespace {

using Set = std::vector<std::pair<std::array<Index, 3>, float>>;

// A 14^3 unit-spaced volume: a 6^3 block of 1 (samples 1..6) in 0, with the listed values set.
Volume block_with(const Set& set) { return test::block_volume(14, set); }

ExtractResult mesh_of(const Volume& v, double thin) {
  RegionSpec spec;
  spec.isovalue = 0.5;
  ExtractOptions opt;
  opt.cell_size = 1;
  opt.thin_features = thin;
  return extract_hex_mesh(make_region(v, spec), opt);
}

// A filament of `n` samples of value `value` along x from the block's face x = 6.
Set filament(int n, float value) {
  Set s;
  for (int i = 0; i < n; ++i) s.push_back({{7 + i, 3, 3}, value});
  return s;
}

TEST(ThinFeatures, FilamentNearTheIsovalueIsCarvedFromItsTip) {
  // Value 0.52 against the isovalue 0.5 beside samples of 0: each sample 0.04 cells from the
  // isosurface, far below a cell.
  const Volume v = block_with(filament(4, 0.52f));
  const ExtractResult kept = mesh_of(v, 0);
  EXPECT_EQ(kept.mesh.num_hexes(), 216 + 4);
  EXPECT_EQ(kept.report.thin_points, 0u);
  const ExtractResult r = mesh_of(v, 0.1);
  EXPECT_EQ(r.report.thin_points, 4u);
  EXPECT_EQ(r.mesh.num_hexes(), 216);
  for (const auto& e : r.report.edits) {
    EXPECT_EQ(e.kind, RepairKind::thin);
    EXPECT_FALSE(e.inside);
    EXPECT_EQ(e.point[1], 3);
    EXPECT_GE(e.point[0], 7);
  }
  const ValidationReport check = validate(r.mesh);
  EXPECT_TRUE(check.valid());
  EXPECT_EQ(check.num_boundary_components, 1u);
  EXPECT_EQ(check.euler_characteristic, 2);
}

TEST(ThinFeatures, ThickFilamentsSheetsAndTheBlockAreKept) {
  // 0.9 beside 0: 0.44 cells from the isosurface, above the fraction.
  EXPECT_EQ(mesh_of(block_with(filament(4, 0.9f)), 0.1).report.thin_points, 0u);
  // A sheet one sample thick (bounded along one axis only), its samples near the isovalue.
  Set sheet;
  for (Index y = 2; y < 6; ++y)
    for (Index z = 2; z < 6; ++z) sheet.push_back({{7, y, z}, 0.52f});
  const ExtractResult s = mesh_of(block_with(sheet), 0.1);
  EXPECT_EQ(s.report.thin_points, 0u);
  EXPECT_EQ(s.mesh.num_hexes(), 216 + 16);
  // The block alone: its corners are bounded along three axes by nothing (neighbours inside).
  EXPECT_EQ(mesh_of(block_with({}), 0.5).report.thin_points, 0u);
}

TEST(ThinFeatures, ClosedLoopHasNoTipAndIsKept) {
  // A square loop of samples near the isovalue, joined to nothing: no sample of it is simple
  // (carving one opens the loop), so it is kept whole.
  Set loop;
  for (Index i = 0; i < 4; ++i) {
    loop.push_back({{8 + i, 8, 8}, 0.52f});
    loop.push_back({{8 + i, 11, 8}, 0.52f});
  }
  for (Index j = 1; j < 3; ++j) {
    loop.push_back({{8, 8 + j, 8}, 0.52f});
    loop.push_back({{11, 8 + j, 8}, 0.52f});
  }
  const ExtractResult r = mesh_of(block_with(loop), 0.1);
  EXPECT_EQ(r.report.thin_points, 0u);
  EXPECT_EQ(r.mesh.num_hexes(), 216 + 12);
}

TEST(ThinFeatures, SpeckIsCarved) {
  const ExtractResult r = mesh_of(block_with({{{10, 10, 10}, 0.52f}}), 0.1);
  EXPECT_EQ(r.report.thin_points, 1u);
  EXPECT_EQ(r.mesh.num_hexes(), 216);
}

}  // namespace
}  // namespace isohex::contour
