// Pillowing: counts, validity, pinches, the boundary, errors, on generated grids.
#include "isohex/error.hpp"
#include "isohex/mesh/generate.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/mesh/validate.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "sheets_support.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <random>
#include <string>
#include <utility>

namespace isohex::test {

/// True if, around every vertex, its hexes are connected through faces containing it (the
/// vertex's neighbourhood is one solid piece, not two touching at a point or an edge).
bool vertices_manifold(const HexMesh& m, std::string& why) {
  const Incidence inc = vertex_hexes(m);
  std::vector<std::array<Index, 6>> nb(m.hexes.size());
  for (const QuadFace& q : build_quads(m)) {
    nb[q.hex[0]][q.local[0]] = q.hex[1];
    if (!q.is_boundary()) nb[q.hex[1]][q.local[1]] = q.hex[0];
  }
  for (Index v = 0; v < m.num_vertices(); ++v) {
    std::vector<Index> hs(inc.ids.begin() + inc.offsets[v], inc.ids.begin() + inc.offsets[v + 1]);
    if (hs.empty()) continue;
    std::vector<Index> stack{hs[0]}, seen{hs[0]};
    while (!stack.empty()) {
      const Index h = stack.back();
      stack.pop_back();
      for (int f = 0; f < 6; ++f) {
        const Index n = nb[h][f];
        bool has_v = false;
        for (int c : kHexFaces[f]) has_v |= m.hexes[h][c] == v;
        if (n < 0 || !has_v || std::find(seen.begin(), seen.end(), n) != seen.end()) continue;
        seen.push_back(n);
        stack.push_back(n);
      }
    }
    if (seen.size() != hs.size()) {
      why = "the hexes around vertex " + std::to_string(v) + " fall apart";
      return false;
    }
  }
  return true;
}

PillowResult checked_pillow(const HexMesh& mesh, const std::vector<std::uint8_t>& set, const PillowOptions& opt) {
  PillowResult r = pillow(mesh, set, opt);
  const HexMesh& m = r.mesh;
  EXPECT_EQ(m.hexes.size(), mesh.hexes.size() + r.interface_quads);
  EXPECT_EQ(m.points.size(), mesh.points.size() + r.interface_vertices + r.pinch_copies);
  EXPECT_EQ(r.copy_of.size(), r.interface_vertices + r.pinch_copies);
  const ValidationReport v = validate(m), v0 = validate(mesh);
  EXPECT_TRUE(v.valid()) << (v.faults.empty() ? "" : v.faults.front().message);
  // The boundary keeps its topology: the new sheet ends on it or (include_boundary) lies inside.
  EXPECT_EQ(v.num_boundary_components, v0.num_boundary_components);
  EXPECT_EQ(v.euler_characteristic, v0.euler_characteristic);
  std::string why;
  EXPECT_TRUE(vertices_manifold(m, why)) << why;
  EXPECT_EQ(r.folded_vertices, 0u);
  EXPECT_EQ(r.inverted_new_hexes, 0u);
  EXPECT_EQ(r.inverted_changed_hexes, 0u);
  for (std::size_t i = 0; i < mesh.points.size(); ++i) EXPECT_EQ(m.points[i], mesh.points[i]);
  const auto before = scaled_jacobians(mesh), after = scaled_jacobians(m);
  std::vector<std::uint8_t> in = set;  // the shrink set after the reported flips
  for (Index h : r.added) EXPECT_EQ(std::exchange(in[h], 1), 0);
  for (Index h : r.removed) EXPECT_NE(std::exchange(in[h], 0), 0);
  std::size_t outside_changed = 0;
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    if (in[h] == 0) outside_changed += m.hexes[h] != mesh.hexes[h];
    if (before[h] > 0 && !is_degenerate(before[h])) {
      EXPECT_GT(after[h], 0) << "hex " << h;
      EXPECT_FALSE(is_degenerate(after[h])) << "hex " << h;
    }
    for (int k = 0; k < 8; ++k) {  // an old hex uses the originals or their copies
      const Index x = m.hexes[h][k];
      EXPECT_EQ(x < mesh.num_vertices() ? x : r.copy_of[x - mesh.num_vertices()], mesh.hexes[h][k]);
    }
  }
  // The outside changes only where it is pinched (it then takes copies too).
  EXPECT_EQ(outside_changed > 0, r.outside_copies > 0);
  for (std::size_t h = mesh.hexes.size(); h < m.hexes.size(); ++h) {
    EXPECT_GT(after[h], 0) << "new hex " << h;
    EXPECT_FALSE(is_degenerate(after[h])) << "new hex " << h;
    EXPECT_GE(after[h], r.min_new_scaled_jacobian);
  }
  return r;
}

bool same_surface(const HexMesh& a, const HexMesh& b) {
  auto key = [](const HexMesh& m) {
    std::vector<std::array<Index, 4>> qs = boundary_quads(m);
    for (auto& q : qs) std::rotate(q.begin(), std::min_element(q.begin(), q.end()), q.end());
    std::sort(qs.begin(), qs.end());
    return qs;
  };
  const auto qa = key(a), qb = key(b);
  if (qa != qb) return false;
  for (const auto& q : qa)
    for (Index v : q)
      if (a.points[v] != b.points[v]) return false;
  return true;
}

namespace {

std::vector<std::uint8_t> only(const HexMesh& m, std::initializer_list<Index> hexes) {
  std::vector<std::uint8_t> s(m.hexes.size(), 0);
  for (Index h : hexes) s[h] = 1;
  return s;
}

Index cell(int i, int j, int k, int nx, int ny) { return i + nx * (j + ny * k); }

TEST(Pillow, OneInteriorHexGetsSixNewHexesAndEightCopies) {
  const HexMesh m = grid_mesh(3, 3, 3);
  const PillowResult r = checked_pillow(m, only(m, {cell(1, 1, 1, 3, 3)}));
  EXPECT_EQ(r.interface_quads, 6u);
  EXPECT_EQ(r.interface_vertices, 8u);
  EXPECT_EQ(r.pinch_copies, 0u);
  EXPECT_EQ(r.reduced_vertices, 0u);
  // A cube corner moves along the diagonal so that each face moves inward by offset × h.
  const Vec3 c = r.mesh.points[m.num_vertices()];
  const Vec3 o = m.points[r.copy_of[0]];
  EXPECT_NEAR((c - o).cwiseAbs().maxCoeff(), 0.25, 1e-12);
  // Frusta 1 × 1 below, 0.5 × 0.5 above, 0.25 high: the worst corner is a cube corner's
  // diagonal against two edges, 1/√3.
  EXPECT_NEAR(r.min_new_scaled_jacobian, 1 / std::sqrt(3.0), 1e-12);
}

TEST(Pillow, TwoHexesTouchingAtAnEdgeArePillowedSeparately) {
  const HexMesh m = grid_mesh(4, 4, 3);
  const PillowResult r = checked_pillow(m, only(m, {cell(1, 1, 1, 4, 4), cell(2, 2, 1, 4, 4)}));
  EXPECT_EQ(r.interface_quads, 12u);
  EXPECT_EQ(r.interface_vertices, 14u);
  EXPECT_EQ(r.pinch_copies, 2u);  // the two ends of the shared edge
}

TEST(Pillow, TwoHexesTouchingAtAVertexArePillowedSeparately) {
  const HexMesh m = grid_mesh(4, 4, 4);
  const PillowResult r = checked_pillow(m, only(m, {cell(1, 1, 1, 4, 4), cell(2, 2, 2, 4, 4)}));
  EXPECT_EQ(r.interface_quads, 12u);
  EXPECT_EQ(r.interface_vertices, 15u);
  EXPECT_EQ(r.pinch_copies, 1u);
}

TEST(Pillow, SeveralComponentsAndAPlanarSheetEndingOnTheBoundary) {
  const HexMesh m = grid_mesh(4, 4, 4);
  std::vector<std::uint8_t> half(m.hexes.size(), 0);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 2; ++i) half[cell(i, j, k, 4, 4)] = 1;
  const PillowResult r = checked_pillow(m, half);
  EXPECT_EQ(r.interface_quads, 16u);
  EXPECT_EQ(r.interface_vertices, 25u);
  // The copies stay on the box faces they started on: the new sheet ends on the boundary.
  for (std::size_t c = 0; c < r.copy_of.size(); ++c) {
    const Vec3& o = m.points[r.copy_of[c]];
    const Vec3& p = r.mesh.points[m.num_vertices() + c];
    EXPECT_DOUBLE_EQ(p.x(), 1.75);
    for (int a = 1; a < 3; ++a)
      if (o[a] == 0 || o[a] == 4) EXPECT_NEAR(p[a], o[a], 1e-12);
  }
  EXPECT_EQ(validate(r.mesh).num_boundary_quads, validate(m).num_boundary_quads + 16);

  auto two = only(m, {cell(0, 0, 0, 4, 4), cell(3, 3, 3, 4, 4), cell(2, 1, 1, 4, 4)});
  const PillowResult r2 = checked_pillow(m, two);
  EXPECT_EQ(r2.interface_quads, 3u + 3u + 6u);
  EXPECT_EQ(r2.pinch_copies, 0u);
}

TEST(Pillow, OuterVertexPinchSplitsTheOutside) {
  // Shrink set = all but two hexes touching at the centre vertex: the shrink set's single fan
  // there is a band between two separate outside regions. No single copy could move away from
  // both, so the band keeps the centre and each outside region gets its own vertex.
  const HexMesh m = grid_mesh(2, 2, 2);
  std::vector<std::uint8_t> s(8, 1);
  s[0] = s[7] = 0;
  const PillowResult r = checked_pillow(m, s);
  EXPECT_EQ(r.interface_quads, 6u);
  EXPECT_EQ(r.interface_vertices, 13u);
  EXPECT_EQ(r.pinch_copies, 1u);   // the centre has three vertices: the band's and two copies
  EXPECT_EQ(r.outside_copies, 2u);
  for (std::size_t c = 0; c < r.copy_of.size(); ++c)
    if (r.copy_of[c] == 13) {  // the copies move into their octants
      const Vec3 d = r.mesh.points[m.num_vertices() + c] - m.points[13];
      EXPECT_TRUE((d.array() < 0).all() || (d.array() > 0).all()) << d.transpose();
    }
}

TEST(Pillow, OuterEdgePinchMergesTheShrinkSide) {
  // Around the centre of a 2³ grid: five shrink-set octants around three outside octants, two
  // of which touch the third only along an edge. Merging the outside along that edge would
  // leave the centre's shrink-set vertex with interface quads facing both ±x and ±z; merging the
  // shrink side instead lets the two outside pieces move apart.
  const HexMesh m = grid_mesh(2, 2, 2);
  const std::vector<std::uint8_t> s = {1, 0, 1, 1, 0, 1, 0, 1};
  const PillowResult r = checked_pillow(m, s);
  EXPECT_EQ(r.interface_quads, 7u);
  EXPECT_GE(r.flipped_edges, 1u);
  EXPECT_GT(r.outside_copies, 0u);
}

TEST(Pillow, UnplaceablePinchIsUndoneByAReportedFlip) {
  // A 2 × 2 × 3 grid; the shrink set is the bottom layer and two diagonal hexes of the middle
  // layer. Around the vertical interior edge, the middle layer alternates. At its lower end
  // the two outside hexes must be separated (merged they would face ±x and ±y, and so would
  // the shrink set), at its upper end the two shrink-set hexes must be (the outside is the
  // top layer plus the other diagonal): no choice of merge sides places both ends.
  const HexMesh m = grid_mesh(2, 2, 3);
  const PillowResult r = checked_pillow(m, only(m, {0, 1, 2, 3, 5, 6}));
  EXPECT_EQ(r.added.size() + r.removed.size(), 1u);
}

TEST(Pillow, CheckerboardPinchedOnBothSides) {
  // Every interior vertex and edge of a 4³ checkerboard is pinched on both sides.
  const HexMesh m = grid_mesh(4, 4, 4);
  std::vector<std::uint8_t> s(m.hexes.size());
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) s[cell(i, j, k, 4, 4)] = (i + j + k) % 2;
  for (bool boundary : {false, true}) {
    const PillowResult r = checked_pillow(m, s, {.include_boundary = boundary});
    EXPECT_GT(r.pinched_edges, 0u);
    EXPECT_GT(r.pinch_copies, 0u);
    EXPECT_TRUE(r.added.empty() && r.removed.empty());
  }
}

/// Random shrink sets on jittered grids, many of them pinched inside, outside or both
/// (checkerboard patches): every one is pillowed with all the checks of checked_pillow.
TEST(Pillow, RandomShrinkSetsOnJitteredGrids) {
  std::mt19937 rng(7);
  int pinched = 0, outer = 0, flipped = 0, adjusted = 0, adjusted_hexes = 0;
  for (int trial = 0; trial < 160; ++trial) {
    const int nx = 3 + trial % 3, ny = 3 + trial % 2, nz = 3;
    HexMesh m = grid_mesh(nx, ny, nz);
    jitter(m, 0.12, static_cast<unsigned>(trial + 1));
    std::vector<std::uint8_t> s(m.hexes.size(), 0);
    const double p = std::uniform_real_distribution<double>(0.1, 0.9)(rng);
    for (auto& f : s) f = std::bernoulli_distribution(p)(rng);
    if (trial % 4 >= 2) {  // a checkerboard patch over a random box, the rest random
      std::uniform_int_distribution<int> x(0, nx - 1), y(0, ny - 1), z(0, nz - 1);
      const int x0 = x(rng), y0 = y(rng), z0 = z(rng), x1 = x(rng), y1 = y(rng), z1 = z(rng);
      for (int k = std::min(z0, z1); k <= std::max(z0, z1); ++k)
        for (int j = std::min(y0, y1); j <= std::max(y0, y1); ++j)
          for (int i = std::min(x0, x1); i <= std::max(x0, x1); ++i)
            s[cell(i, j, k, nx, ny)] = (i + j + k + trial / 4) % 2;
    }
    if (std::count(s.begin(), s.end(), 1) == 0) s[0] = 1;
    if (std::count(s.begin(), s.end(), 1) == static_cast<long>(s.size())) s[0] = 0;
    PillowOptions opt;
    opt.include_boundary = trial % 2 == 1;
    SCOPED_TRACE("trial " + std::to_string(trial));
    const PillowResult r = checked_pillow(m, s, opt);
    pinched += r.pinch_copies > 0;
    outer += r.outside_copies > 0;
    flipped += r.flipped_edges > 0;
    adjusted += !r.added.empty() || !r.removed.empty();
    adjusted_hexes += static_cast<int>(r.added.size() + r.removed.size());
  }
  std::printf("160 random shrink sets: %d pinched, %d with outside copies, %d with flipped edges, %d adjusted "
              "(%d hexes flipped in all)\n", pinched, outer, flipped, adjusted, adjusted_hexes);
  EXPECT_GE(pinched, 100);
  EXPECT_GE(outer, 40);
  EXPECT_GE(flipped, 10);
}

TEST(Pillow, BoundarySheetsKeepTheSurfaceBitIdentical) {
  HexMesh cavity = grid_mesh(5, 5, 5);
  cavity.hexes.erase(cavity.hexes.begin() + cell(2, 2, 2, 5, 5));
  HexMesh jittered = box_mesh(3, 4, 5, Vec3(-1, 0, 2), Vec3(0.5, 1, 3));
  jitter(jittered, 0.02, 3);
  for (const HexMesh* m : {&jittered, &cavity}) {
    const std::size_t bq = validate(*m).num_boundary_quads, bv = validate(*m).num_boundary_vertices;
    const PillowResult r = checked_pillow(*m, std::vector<std::uint8_t>(m->hexes.size(), 1), {.include_boundary = true});
    EXPECT_EQ(r.interface_quads, bq);
    EXPECT_EQ(r.interface_vertices, bv);
    EXPECT_TRUE(same_surface(*m, r.mesh));
    EXPECT_GT(count_multi_boundary_hexes(*m), 0u);
    EXPECT_EQ(count_multi_boundary_hexes(r.mesh), 0u);
  }
  const HexMesh ball = ball_mesh(6);
  const PillowResult r = pillow_boundary(ball);
  EXPECT_TRUE(same_surface(ball, r.mesh));
  EXPECT_TRUE(validate(r.mesh).valid());
  EXPECT_GT(r.min_new_scaled_jacobian, 0);
  EXPECT_EQ(count_multi_boundary_hexes(r.mesh), 0u);
}

TEST(Pillow, OneBlockGetsAnEnclosingSheet) {
  HexMesh m = grid_mesh(4, 3, 3);
  m.blocks.assign(m.hexes.size(), 0);
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j) m.blocks[cell(3, j, k, 4, 3)] = 5;
  m.fixed.assign(m.points.size(), 1);
  const PillowResult r = pillow_boundary(m, 5);
  EXPECT_EQ(r.interface_quads, 9u + 9u + 3u * 4u);  // the x = 3 face, the outer x face, 4 sides
  EXPECT_TRUE(same_surface(m, r.mesh));
  EXPECT_TRUE(validate(r.mesh).valid());
  ASSERT_EQ(r.mesh.blocks.size(), r.mesh.hexes.size());
  for (std::size_t h = m.hexes.size(); h < r.mesh.hexes.size(); ++h) EXPECT_EQ(r.mesh.blocks[h], 5);
  ASSERT_EQ(r.mesh.fixed.size(), r.mesh.points.size());
  EXPECT_EQ(r.mesh.fixed.back(), 0);  // copies are free to move
  EXPECT_THROW(pillow_boundary(m, 9), Error);
}

// A copy placed outside PillowOptions' domain is clamped into it: on a 4 x 3 x 3 grid whose
// x = 4 face's copies land at x = 3.75, a domain ending at x = 3.6 holds them at 3.6.
TEST(Pillow, CopiesAreClampedIntoTheDomain) {
  const HexMesh m = grid_mesh(4, 3, 3);
  PillowOptions opt;
  opt.domain_hi = Vec3(3.6, 10, 10);
  const PillowResult r = pillow_boundary(m, -1, opt);
  EXPECT_EQ(r.clamped_vertices, 4u * 4u);  // the copies of the x = 4 face's vertices
  for (std::size_t v = m.points.size(); v < r.mesh.points.size(); ++v) EXPECT_LE(r.mesh.points[v].x(), 3.6);
  EXPECT_TRUE(same_surface(m, r.mesh));
  EXPECT_TRUE(validate(r.mesh).valid());
  EXPECT_GT(r.min_new_scaled_jacobian, 0);
  EXPECT_EQ(pillow_boundary(m).clamped_vertices, 0u);
}

TEST(Pillow, BadInputIsRefusedWithAClearMessage) {
  const HexMesh m = grid_mesh(2, 2, 2);
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] { pillow(m, std::vector<std::uint8_t>(8, 0)); }).find("empty"), std::string::npos);
  EXPECT_NE(message([&] { pillow(m, std::vector<std::uint8_t>(8, 1)); }).find("no interface"), std::string::npos);
  EXPECT_NE(message([&] { pillow(m, std::vector<std::uint8_t>(3, 1)); }).find("3 flags"), std::string::npos);
  EXPECT_NE(message([&] { pillow(m, only(m, {0}), {.offset = 1.5}); }).find("offset"), std::string::npos);
  HexMesh bad = m;
  bad.hexes[1][0] = bad.hexes[1][1];  // repeated vertex
  EXPECT_NE(message([&] { pillow(bad, only(bad, {0})); }).find("input mesh is invalid"), std::string::npos);
}

}  // namespace
}  // namespace isohex::test
