// The dual-contouring mesher on constructed voxel sets: the cell-case table, the manifold
// repair, and a property test over random volumes (the boundary must always be a closed,
// consistently oriented 2-manifold and the mesh conformal).
#include "isohex/contour/cell_cases.hpp"
#include "isohex/contour/dual_contour.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/mesh/validate.hpp"
#include "isohex/quality/hex_quality.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdlib>
#include <random>
#include <vector>

namespace isohex::contour {
namespace {

// A unit-spaced volume of n^3 points: 1 at the listed points, 0 elsewhere.
Volume voxels(Index n, const std::vector<std::array<Index, 3>>& inside) {
  Volume v;
  v.dims = {n, n, n};
  v.values.assign(v.size(), 0.0f);
  for (const auto& p : inside) v.at(p[0], p[1], p[2]) = 1.0f;
  return v;
}

struct Meshed {
  ExtractResult result;
  ValidationReport check;
};

// Meshes {value > 0.5} at the volume's own spacing (the grid is the voxel grid).
Meshed mesh_of(const Volume& v, Index min_component = 0) {
  RegionSpec spec;
  spec.isovalue = 0.5;
  const Region region = make_region(v, spec);
  ExtractOptions opt;
  opt.cell_size = 1;
  opt.min_component = min_component;
  Meshed m{extract_hex_mesh(region, opt), {}};
  m.check = validate(m.result.mesh);
  return m;
}

void expect_closed_manifold(const Meshed& m) {
  EXPECT_TRUE(m.check.valid()) << (m.check.faults.empty() ? "" : m.check.faults.front().message);
  EXPECT_EQ(m.check.count(FaultKind::unused_vertex), 0u);
  EXPECT_TRUE(m.check.topology_checked);
  // A closed surface: every boundary edge has two quads, so 2E = 4F.
  EXPECT_EQ(2 * m.check.num_boundary_edges, 4 * m.check.num_boundary_quads);
}

// Components of the inside points (6-adjacency) and of the outside points (18-adjacency,
// counting the space around the volume as outside): marching cubes' topology of the samples.
struct DigitalTopology {
  int inside = 0, outside = 0;
  bool operator==(const DigitalTopology&) const = default;
};
DigitalTopology digital_topology(const std::vector<std::uint8_t>& in, Index n) {
  const Index m = n + 2;  // padded by one outside point on every side
  std::vector<int> label(static_cast<std::size_t>(m * m * m), -1);
  auto flag = [&](Index x, Index y, Index z) -> int {
    if (x < 1 || y < 1 || z < 1 || x > n || y > n || z > n) return 0;
    return in[static_cast<std::size_t>((x - 1) + n * ((y - 1) + n * (z - 1)))];
  };
  DigitalTopology t;
  for (Index s = 0; s < m * m * m; ++s) {
    if (label[static_cast<std::size_t>(s)] >= 0) continue;
    const Index sx = s % m, sy = s / m % m, sz = s / (m * m);
    const int value = flag(sx, sy, sz), reach = value ? 1 : 2;
    ++(value ? t.inside : t.outside);
    std::vector<Index> stack{s};
    label[static_cast<std::size_t>(s)] = 1;
    while (!stack.empty()) {
      const Index p = stack.back();
      stack.pop_back();
      const Index px = p % m, py = p / m % m, pz = p / (m * m);
      for (Index dz = -1; dz <= 1; ++dz)
        for (Index dy = -1; dy <= 1; ++dy)
          for (Index dx = -1; dx <= 1; ++dx) {
            const Index d = std::abs(dx) + std::abs(dy) + std::abs(dz);
            const Index x = px + dx, y = py + dy, z = pz + dz;
            if (d == 0 || d > reach || x < 0 || y < 0 || z < 0 || x >= m || y >= m || z >= m) continue;
            const Index q = x + m * (y + m * z);
            if (label[static_cast<std::size_t>(q)] < 0 && flag(x, y, z) == value) {
              label[static_cast<std::size_t>(q)] = 1;
              stack.push_back(q);
            }
          }
    }
  }
  return t;
}

// Flags of the volume's points (value > 0.5) with the repair's edits applied: all of them,
// or only those that keep the topology (simple and relocated).
std::vector<std::uint8_t> repaired_flags(const Volume& v, const ExtractReport& r, bool simple_only) {
  std::vector<std::uint8_t> in(v.values.size());
  for (std::size_t i = 0; i < in.size(); ++i) in[i] = v.values[i] > 0.5f;
  for (const auto& e : r.edits)
    if (e.keeps_topology() || !simple_only)
      in[static_cast<std::size_t>(e.point[0] + v.dims[0] * (e.point[1] + v.dims[1] * e.point[2]))] = e.inside;
  return in;
}

TEST(ContourCellCases, ComponentsAndManifoldness) {
  EXPECT_EQ(cell_case(0).num_components, 0);
  EXPECT_EQ(cell_case(0xff).num_components, 1);
  EXPECT_TRUE(cell_case(0xff).manifold);
  // Corners 0 and 7 touch at the cell centre only: two vertices, each fine on its own.
  EXPECT_EQ(cell_case(0x81).num_components, 2);
  EXPECT_TRUE(cell_case(0x81).manifold);
  // Corners 0 and 3 share only a face diagonal: split too.
  EXPECT_EQ(cell_case(0x09).num_components, 2);
  EXPECT_EQ(cell_case(0x09).component[0], 0);
  EXPECT_EQ(cell_case(0x09).component[3], 1);
  // Six inside around two opposite outside corners: one component, two outside parts.
  EXPECT_EQ(cell_case(0x7e).num_components, 1);
  EXPECT_FALSE(cell_case(0x7e).manifold);
  EXPECT_EQ(manifold_fill(0x7e, 0), 0x80);     // equal parts: keep the lowest corner's
  EXPECT_EQ(manifold_fill(0x7e, 0x80), 0x01);  // corner 7 must stay outside
  EXPECT_EQ(manifold_fill(0x81, 0), 0);
}

TEST(ContourCellCases, RepeatedFillAlwaysReachesAManifoldCell) {
  for (int m = 0; m < 256; ++m)
    for (std::uint8_t fixed : {std::uint8_t{0}, std::uint8_t{0x0f}, std::uint8_t{0x55}}) {
      auto mask = static_cast<std::uint8_t>(m & ~fixed);
      for (int round = 0; round < 8 && !cell_case(mask).manifold; ++round) {
        const std::uint8_t f = manifold_fill(mask, fixed);
        ASSERT_NE(f, 0) << "mask " << m;
        ASSERT_EQ(f & mask, 0);
        ASSERT_EQ(f & fixed, 0);
        mask |= f;
      }
      EXPECT_TRUE(cell_case(mask).manifold) << "mask " << m;
    }
}

TEST(ContourManifold, SingleVoxelIsOneHexBoundedBySixQuads) {
  const Meshed m = mesh_of(voxels(3, {{1, 1, 1}}));
  expect_closed_manifold(m);
  EXPECT_EQ(m.result.mesh.num_hexes(), 1);
  EXPECT_EQ(m.check.num_boundary_quads, 6u);
  EXPECT_EQ(m.check.euler_characteristic, 2);
  EXPECT_GT(volume(m.result.mesh.corners(0)), 0);
}

TEST(ContourManifold, CubesSharingAnEdgeAreSeparated) {
  const Meshed m = mesh_of(voxels(5, {{1, 1, 1}, {2, 2, 1}}));
  expect_closed_manifold(m);
  EXPECT_EQ(m.check.num_boundary_components, 2u);
  EXPECT_EQ(m.check.euler_characteristic, 4);
  EXPECT_EQ(m.result.report.split_cells, 2u);  // the two cells on either side of the shared edge
}

TEST(ContourManifold, CubesSharingAVertexAreSeparated) {
  const Meshed m = mesh_of(voxels(5, {{1, 1, 1}, {2, 2, 2}}));
  expect_closed_manifold(m);
  EXPECT_EQ(m.check.num_boundary_components, 2u);
  EXPECT_EQ(m.check.euler_characteristic, 4);
}

// A 6^3 solid with the listed one-voxel cavities.
Volume block_with_cavities(const std::vector<std::array<Index, 3>>& cavities) {
  Volume v = voxels(8, {});
  for (Index z = 1; z < 7; ++z)
    for (Index y = 1; y < 7; ++y)
      for (Index x = 1; x < 7; ++x) v.at(x, y, z) = 1.0f;
  for (const auto& c : cavities) v.at(c[0], c[1], c[2]) = 0.0f;
  return v;
}

TEST(ContourManifold, CavitiesTouchingAtAVertexAreKeptByMovingOne) {
  // Two single-voxel cavities meeting at a vertex (a cell's body diagonal): marching cubes
  // sees two cavities, but no conformal mesh with one hex per inside point can have them
  // there, and every single flip changes the topology. The repair moves one cavity: (3, 3, 3)
  // is made inside and (2, 2, 2), the first place within 2 samples whose 26 neighbours are
  // then all inside, outside. Outer surface and two cavities: 3 spheres.
  const Volume v = block_with_cavities({{3, 3, 3}, {4, 4, 4}});
  const Meshed m = mesh_of(v);
  expect_closed_manifold(m);
  const ExtractReport& r = m.result.report;
  EXPECT_EQ(r.forced_points, 0u);
  EXPECT_EQ(r.simple_points, 0u);
  EXPECT_EQ(r.relocated_points, 2u);
  ASSERT_EQ(r.edits.size(), 2u);
  EXPECT_EQ(r.edits[0].point, (std::array<Index, 3>{3, 3, 3}));
  EXPECT_TRUE(r.edits[0].inside);
  EXPECT_EQ(r.edits[1].point, (std::array<Index, 3>{2, 2, 2}));
  EXPECT_FALSE(r.edits[1].inside);
  EXPECT_EQ(r.edits[0].kind, RepairKind::relocated);
  EXPECT_EQ(m.result.mesh.num_hexes(), 6 * 6 * 6 - 2);
  EXPECT_EQ(m.check.num_boundary_components, 3u);
  EXPECT_EQ(m.check.euler_characteristic, 6);
  std::vector<std::uint8_t> before(v.values.size());
  for (std::size_t i = 0; i < before.size(); ++i) before[i] = v.values[i] > 0.5f;
  EXPECT_EQ(digital_topology(repaired_flags(v, r, false), 8), digital_topology(before, 8));
  // The moved cavity's vertices are still on the isosurface (around the filled point).
  RegionSpec spec;
  spec.isovalue = 0.5;
  const SurfaceDistance d = surface_distance(make_region(v, spec), m.result.mesh, m.result.vertex_place);
  EXPECT_LE(d.max_relative, 1e-6);
}

// Boundary quads whose 4 vertices coincide (zero area, all edges of length 0).
std::size_t collapsed_boundary_quads(const HexMesh& mesh) {
  std::size_t n = 0;
  for (const Quad& q : boundary_quads(mesh)) {
    bool all = true;
    for (int c = 1; c < 4; ++c) all = all && mesh.points[static_cast<std::size_t>(q[c])] == mesh.points[static_cast<std::size_t>(q[0])];
    n += all;
  }
  return n;
}

TEST(ContourManifold, ZeroVolumeCavityIsFilled) {
  // Two one-sample cavities in a 6^3 solid: (4, 4, 4) below the isovalue (a real cavity, a
  // small octahedron), (2, 2, 2) exactly at it (L == 0, outside): its isosurface is that one
  // point, and dual contouring would put all 8 vertices around it there, a closed boundary of
  // 6 collapsed quads. It is filled; the real one is kept.
  Volume v = block_with_cavities({{4, 4, 4}});
  v.at(2, 2, 2) = 0.5f;
  const Meshed m = mesh_of(v);
  expect_closed_manifold(m);
  const ExtractReport& r = m.result.report;
  EXPECT_EQ(r.degenerate_components, 1u);
  EXPECT_EQ(r.degenerate_points, 1u);
  EXPECT_EQ(r.filled_points, 1u);
  EXPECT_EQ(r.forced_points, 0u);
  ASSERT_EQ(r.edits.size(), 1u);
  EXPECT_EQ(r.edits[0].point, (std::array<Index, 3>{2, 2, 2}));
  EXPECT_TRUE(r.edits[0].inside);
  EXPECT_EQ(r.edits[0].kind, RepairKind::degenerate);
  EXPECT_FALSE(r.edits[0].keeps_topology());
  EXPECT_EQ(m.result.mesh.num_hexes(), 6 * 6 * 6 - 1);
  EXPECT_EQ(m.check.num_boundary_components, 2u);  // the outer surface and the real cavity
  EXPECT_EQ(m.check.euler_characteristic, 4);
  EXPECT_EQ(collapsed_boundary_quads(m.result.mesh), 0u);
  for (double sj : scaled_jacobians(m.result.mesh)) EXPECT_FALSE(is_degenerate(sj));
  RegionSpec spec;
  spec.isovalue = 0.5;
  const SurfaceDistance d = surface_distance(make_region(v, spec), m.result.mesh, m.result.vertex_place);
  EXPECT_LE(d.max_relative, 1e-6);
  EXPECT_EQ(d.off_surface, 0u);
}

TEST(ContourManifold, CavityJustBelowTheIsovalueIsKept) {
  // Only exact zeros count: the same solid with that point one float below the isovalue has
  // two real cavities (tiny, but with a volume), both kept.
  Volume v = block_with_cavities({{4, 4, 4}});
  v.at(2, 2, 2) = std::nextafter(0.5f, 0.0f);
  const Meshed m = mesh_of(v);
  expect_closed_manifold(m);
  EXPECT_EQ(m.result.report.degenerate_components, 0u);
  EXPECT_TRUE(m.result.report.edits.empty());
  EXPECT_EQ(m.check.num_boundary_components, 3u);
  EXPECT_EQ(m.result.mesh.num_hexes(), 6 * 6 * 6 - 2);
}

TEST(ContourManifold, LargerZeroCavitiesAreFilledOnlyWithoutVolume) {
  // Two face-adjacent samples at the isovalue: a segment, no volume: filled as one cavity.
  {
    Volume v = block_with_cavities({});
    v.at(3, 3, 3) = 0.5f;
    v.at(4, 3, 3) = 0.5f;
    const Meshed m = mesh_of(v);
    expect_closed_manifold(m);
    EXPECT_EQ(m.result.report.degenerate_components, 1u);
    EXPECT_EQ(m.result.report.degenerate_points, 2u);
    EXPECT_EQ(m.check.num_boundary_components, 1u);
    EXPECT_EQ(collapsed_boundary_quads(m.result.mesh), 0u);
  }
  // A 2 x 2 x 2 block at the isovalue: L == 0 throughout its cell, a cube-shaped cavity with
  // a real volume: kept.
  {
    Volume v = block_with_cavities({});
    for (Index z = 3; z < 5; ++z)
      for (Index y = 3; y < 5; ++y)
        for (Index x = 3; x < 5; ++x) v.at(x, y, z) = 0.5f;
    const Meshed m = mesh_of(v);
    expect_closed_manifold(m);
    EXPECT_EQ(m.result.report.degenerate_components, 0u);
    EXPECT_EQ(m.check.num_boundary_components, 2u);
    EXPECT_EQ(m.result.mesh.num_hexes(), 6 * 6 * 6 - 8);
  }
  // A sample at the isovalue next to (across a face diagonal) one below it: one cavity with a
  // volume, kept whole.
  {
    Volume v = block_with_cavities({{4, 4, 3}});
    v.at(3, 3, 3) = 0.5f;
    const Meshed m = mesh_of(v);
    expect_closed_manifold(m);
    EXPECT_EQ(m.result.report.degenerate_components, 0u);
    EXPECT_EQ(m.check.num_boundary_components, 2u);
  }
  // A sample at the isovalue on the solid's outer surface is not a cavity: kept.
  {
    Volume v = block_with_cavities({});
    v.at(1, 3, 3) = 0.5f;
    const Meshed m = mesh_of(v);
    expect_closed_manifold(m);
    EXPECT_EQ(m.result.report.degenerate_components, 0u);
    EXPECT_EQ(m.result.mesh.num_hexes(), 6 * 6 * 6 - 1);
  }
}

TEST(ContourManifold, ThreeCavitiesOnADiagonalKeepTheirTopology) {
  // A chain of three cavities touching at vertices: the outer ones have nowhere to go within
  // 2 samples that touches neither of the others, so the middle one is moved off the
  // diagonal; four spheres in all.
  const Volume v = block_with_cavities({{2, 2, 2}, {3, 3, 3}, {4, 4, 4}});
  const Meshed m = mesh_of(v);
  expect_closed_manifold(m);
  EXPECT_EQ(m.result.report.forced_points, 0u);
  EXPECT_EQ(m.check.num_boundary_components, 4u);
  EXPECT_EQ(m.check.euler_characteristic, 8);
  EXPECT_EQ(m.result.mesh.num_hexes(), 6 * 6 * 6 - 3);
}

TEST(ContourManifold, IslandsTouchingAtAVertexNeedNoRepair) {
  // The complement: two single inside points meeting at a vertex in the outside. Each cell
  // gives each its own dual vertex, so nothing is flipped: two cubes, as marching cubes has.
  const Meshed m = mesh_of(voxels(6, {{2, 2, 2}, {3, 3, 3}}));
  expect_closed_manifold(m);
  EXPECT_TRUE(m.result.report.edits.empty());
  EXPECT_EQ(m.check.num_boundary_components, 2u);
  EXPECT_EQ(m.check.euler_characteristic, 4);
}

TEST(ContourManifold, CavitiesTouchingAlongAnEdgeAreJoined) {
  // Marching cubes joins these two cavities through the edge (the inside corners of the
  // ambiguous face are kept apart): one cavity. With one dual vertex per inside component the
  // cell above the edge would pinch. Filling one of the two cavity points is simple (one
  // cavity remains), as is carving an inside point of that face (an L-shaped cavity); with
  // equal levels the repair takes the first corner of the cell, the fill of (3, 3, 3).
  std::vector<std::array<Index, 3>> in;
  for (Index z = 1; z < 7; ++z)
    for (Index y = 1; y < 7; ++y)
      for (Index x = 1; x < 7; ++x)
        if (!(x == 3 && y == 3 && z == 3) && !(x == 4 && y == 4 && z == 3)) in.push_back({x, y, z});
  const Meshed m = mesh_of(voxels(8, in));
  expect_closed_manifold(m);
  EXPECT_EQ(m.result.report.carved_points, 0u);
  EXPECT_EQ(m.result.report.filled_points, 1u);
  EXPECT_EQ(m.result.report.simple_points, 1u);
  EXPECT_EQ(m.result.report.forced_points, 0u);
  ASSERT_EQ(m.result.report.edits.size(), 1u);
  EXPECT_EQ(m.result.report.edits[0].point, (std::array<Index, 3>{3, 3, 3}));
  EXPECT_EQ(m.result.mesh.num_hexes(), 6 * 6 * 6 - 1);
  EXPECT_EQ(m.check.num_boundary_components, 2u);
  EXPECT_EQ(m.check.euler_characteristic, 4);
}

TEST(ContourManifold, CarveTakesTheWeakerInsidePoint) {
  // As above, but of the two inside points on the ambiguous face, (3, 4, 3) is nearer the
  // isosurface: it is the one carved.
  Volume v = voxels(8, {});
  for (Index z = 1; z < 7; ++z)
    for (Index y = 1; y < 7; ++y)
      for (Index x = 1; x < 7; ++x)
        if (!(x == 3 && y == 3 && z == 3) && !(x == 4 && y == 4 && z == 3)) v.at(x, y, z) = 1.0f;
  v.at(3, 4, 3) = 0.6f;
  const Meshed m = mesh_of(v);
  expect_closed_manifold(m);
  EXPECT_EQ(m.result.report.carved_points, 1u);
  // Hexes are numbered in grid order: point (3, 4, 3) is gone, (4, 3, 3) is not. Their hex
  // centroids (mean of corners) lie within half a cell of the point.
  bool has_433 = false, has_343 = false;
  for (Index h = 0; h < m.result.mesh.num_hexes(); ++h) {
    Vec3 c = Vec3::Zero();
    for (const Vec3& p : m.result.mesh.corners(h)) c += p / 8;
    has_433 |= (c - Vec3(4, 3, 3)).norm() < 0.5;
    has_343 |= (c - Vec3(3, 4, 3)).norm() < 0.5;
  }
  EXPECT_TRUE(has_433);
  EXPECT_FALSE(has_343);
}

TEST(ContourManifold, CarvingNeverCutsARod) {
  // A one-point-thick rod bent round an outside point: in the cell at (1..2, 1..2, 1..2) the
  // rod's points (2, 1, 1) and (1, 2, 1) sit on one face's diagonal, the outside points
  // (1, 1, 1) and (2, 2, 1) on the other, and the rod joins them through the cell: an edge
  // contact. Both carve candidates are rod points whose removal would cut the rod in two, so
  // nothing is carved; the fill makes (2, 2, 1) inside and the rod stays one piece.
  const std::vector<std::array<Index, 3>> rod = {{3, 1, 1}, {2, 1, 1}, {2, 1, 2}, {2, 2, 2},
                                                 {1, 2, 2}, {1, 2, 1}, {1, 3, 1}};
  const Meshed m = mesh_of(voxels(6, rod));
  expect_closed_manifold(m);
  EXPECT_EQ(m.result.report.carved_points, 0u);
  EXPECT_EQ(m.result.report.filled_points, 1u);
  EXPECT_EQ(m.result.mesh.num_hexes(), 8);
  EXPECT_EQ(m.check.num_boundary_components, 1u);
  EXPECT_EQ(m.check.euler_characteristic, 2);
}

TEST(ContourManifold, CarvingShortensARodEnd) {
  // The same bend without the rod's two end points: now (2, 1, 1) and (1, 2, 1) are ends, and
  // carving an end changes no topology, so the repair carves one of them and fills nothing.
  const std::vector<std::array<Index, 3>> rod = {{2, 1, 1}, {2, 1, 2}, {2, 2, 2}, {1, 2, 2}, {1, 2, 1}};
  const Meshed m = mesh_of(voxels(6, rod));
  expect_closed_manifold(m);
  EXPECT_EQ(m.result.report.carved_points, 1u);
  EXPECT_EQ(m.result.report.filled_points, 0u);
  EXPECT_EQ(m.result.mesh.num_hexes(), 4);
  EXPECT_EQ(m.check.num_boundary_components, 1u);
  EXPECT_EQ(m.check.euler_characteristic, 2);
}

TEST(ContourManifold, CheckerboardGivesSeparateCubes) {
  std::vector<std::array<Index, 3>> in;
  for (Index z = 1; z < 5; ++z)
    for (Index y = 1; y < 5; ++y)
      for (Index x = 1; x < 5; ++x)
        if ((x + y + z) % 2 == 0) in.push_back({x, y, z});
  const Meshed m = mesh_of(voxels(6, in));
  expect_closed_manifold(m);
  EXPECT_EQ(m.check.num_boundary_components, in.size());
  EXPECT_EQ(m.check.euler_characteristic, 2 * static_cast<long>(in.size()));
  for (Index h = 0; h < m.result.mesh.num_hexes(); ++h) EXPECT_GT(volume(m.result.mesh.corners(h)), 0);
}

TEST(ContourManifold, OneVoxelSpikeOnABlock) {
  std::vector<std::array<Index, 3>> in;
  for (Index z = 1; z < 4; ++z)
    for (Index y = 1; y < 6; ++y)
      for (Index x = 1; x < 6; ++x) in.push_back({x, y, z});
  in.push_back({3, 3, 4});
  in.push_back({3, 3, 5});
  const Meshed m = mesh_of(voxels(8, in));
  expect_closed_manifold(m);
  EXPECT_EQ(m.check.num_boundary_components, 1u);
  EXPECT_EQ(m.check.euler_characteristic, 2);
  EXPECT_EQ(m.result.mesh.num_hexes(), static_cast<Index>(in.size()));
}

TEST(ContourManifold, SolidCutByTheBoxIsClosedByItsFaces) {
  // Everything inside: the boundary is the box itself, vertices on its faces.
  Volume v = voxels(4, {});
  std::fill(v.values.begin(), v.values.end(), 1.0f);
  const Meshed m = mesh_of(v);
  expect_closed_manifold(m);
  EXPECT_EQ(m.result.mesh.num_hexes(), 64);
  EXPECT_EQ(m.check.euler_characteristic, 2);
  double total = 0;
  for (Index h = 0; h < m.result.mesh.num_hexes(); ++h) total += volume(m.result.mesh.corners(h));
  EXPECT_NEAR(total, 27.0, 1e-12);  // exactly the volume's box [0, 3]^3
  EXPECT_EQ(m.result.report.box_vertices, m.check.num_boundary_vertices);
}

TEST(ContourManifold, SmallComponentsAreDropped) {
  const Meshed m = mesh_of(voxels(8, {{1, 1, 1}, {4, 4, 4}, {4, 4, 5}, {4, 5, 5}}), 2);
  expect_closed_manifold(m);
  EXPECT_EQ(m.result.mesh.num_hexes(), 3);
  EXPECT_EQ(m.result.report.dropped_components, 1u);
  EXPECT_EQ(m.result.report.components, 1u);
}

// Property test: random small volumes (noise at several densities, some touching the box)
// always give a valid conformal mesh with a closed manifold boundary.
TEST(ContourManifold, RandomVolumesAlwaysGiveManifolds) {
  std::mt19937 rng(20060606);
  std::size_t forced = 0, simple = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Index n = 4 + trial % 5;
    const double density = 0.2 + 0.6 * (trial % 7) / 6.0;
    Volume v = voxels(n, {});
    std::uniform_real_distribution<float> u(0, 1);
    for (float& x : v.values) x = u(rng) < density ? 1.0f : 0.0f;
    const Meshed m = mesh_of(v);
    SCOPED_TRACE(testing::Message() << "trial " << trial << " n " << n << " density " << density);
    expect_closed_manifold(m);
    EXPECT_EQ(m.check.euler_characteristic % 2, 0);
    // Simple flips keep marching cubes' topology of the samples; with every flip applied the
    // mesh has that topology: one boundary per inside part and per cavity.
    const ExtractReport& r = m.result.report;
    EXPECT_EQ(r.simple_points + r.relocated_points + r.forced_points + r.degenerate_points, r.edits.size());
    std::vector<std::uint8_t> before(v.values.size());
    for (std::size_t i = 0; i < before.size(); ++i) before[i] = v.values[i] > 0.5f;
    EXPECT_EQ(digital_topology(repaired_flags(v, r, true), n), digital_topology(before, n));
    const DigitalTopology after = digital_topology(repaired_flags(v, r, false), n);
    EXPECT_EQ(m.check.num_boundary_components, static_cast<std::size_t>(after.inside + after.outside - 1));
    if (r.forced_points == 0) EXPECT_EQ(after, digital_topology(before, n));
    forced += r.forced_points;
    simple += r.simple_points;
    if (HasFailure()) break;
  }
  // Random noise needs many flips, and most keep the topology.
  EXPECT_GT(simple, 4 * forced);
}

// The same with a smooth random field and a non-aligned grid (vertices placed by the QEF).
TEST(ContourManifold, RandomSmoothFieldsOffGridAlwaysGiveManifolds) {
  std::mt19937 rng(42);
  for (int trial = 0; trial < 60; ++trial) {
    Volume v = voxels(7, {});
    std::normal_distribution<float> g(0, 1);
    for (float& x : v.values) x = g(rng);
    RegionSpec spec;
    spec.isovalue = 0.1 * (trial % 5);
    const Region region = make_region(v, spec);
    ExtractOptions opt;
    opt.cell_size = 0.37 + 0.05 * (trial % 3);
    const ExtractResult r = extract_hex_mesh(region, opt);
    const ValidationReport check = validate(r.mesh);
    SCOPED_TRACE(testing::Message() << "trial " << trial);
    EXPECT_TRUE(check.valid()) << (check.faults.empty() ? "" : check.faults.front().message);
    const SurfaceDistance d = surface_distance(region, r.mesh, r.vertex_place);
    EXPECT_LE(d.max_relative, 1e-6);
    EXPECT_EQ(d.off_surface, 0u);
    if (HasFailure()) break;
  }
}

}  // namespace
}  // namespace isohex::contour
