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

TEST(ContourManifold, PillarsTouchingAlongAnEdgeAreKeptByMovingATunnel) {
  // The 12 x 12 x 12 samples of cthead at h = 1 and iso 600 around grid point (94, 50, 161)
  // (twice the level, value - 600, as sampled), framed by one outside layer. After the simple
  // flips, layer z = 6 is mostly outside between two slabs; two one-sample-thick pillars
  // through it, (5, 6, 6) and (6, 7, 6), touch along a cell edge, beside a third pillar and
  // holes in the slabs, and no sequence of simple flips the searches try mends the two cells
  // (forced flips before the tunnel move). The tunnel move fills
  // the point between the pillars (a tunnel closed) and carves a point of the slab above
  // that joins two outside parts (a tunnel opened): marching cubes' topology kept (one
  // component, Euler characteristic -26 by vtkFlyingEdges3D on the samples), no forced flip.
  static const int values[12 * 12 * 12] = {
      948, 1032, 1080, 1084, 1048, 1028, 1026, 1034, 1052, 1064, 1048, 1002, 1038, 1062, 1102, 1062, 1032, 1030, 1030, 1016, 1006, 1016, 1020, 994,
      986, 1004, 1040, 1044, 1054, 1022, 1040, 1004, 982, 986, 966, 970, 970, 946, 948, 972, 1024, 1028, 1034, 1000, 968, 944, 954, 944,
      992, 946, 906, 926, 956, 990, 1028, 1002, 982, 946, 946, 930, 960, 948, 930, 916, 918, 944, 970, 990, 990, 976, 982, 950,
      942, 918, 914, 932, 918, 908, 920, 948, 996, 1012, 1016, 978, 936, 914, 902, 902, 904, 912, 938, 924, 936, 970, 1000, 988,
      934, 924, 912, 898, 890, 930, 944, 934, 902, 910, 940, 992, 932, 938, 914, 892, 900, 906, 918, 940, 912, 880, 898, 944,
      922, 922, 886, 898, 902, 900, 922, 926, 904, 894, 904, 926, 908, 922, 912, 900, 902, 912, 910, 882, 882, 880, 890, 896,
      1011, 1055, 1040, 1069, 1010, 969, 983, 993, 1002, 1023, 1001, 934, 1105, 1048, 1046, 1097, 1060, 990, 965, 988, 997, 985, 953, 923,
      1068, 1032, 1088, 1126, 1093, 1019, 997, 967, 966, 957, 902, 876, 1001, 990, 1075, 1100, 1099, 1061, 1031, 992, 928, 874, 875, 883,
      930, 913, 1011, 1078, 1085, 1065, 1054, 1015, 928, 863, 859, 889, 886, 849, 939, 1026, 1038, 1027, 1018, 1005, 947, 915, 939, 910,
      869, 828, 896, 992, 1010, 984, 943, 933, 956, 962, 998, 989, 887, 879, 928, 972, 960, 942, 924, 884, 913, 963, 1000, 976,
      900, 929, 973, 960, 950, 916, 890, 901, 905, 932, 952, 993, 894, 977, 988, 964, 947, 884, 879, 926, 935, 904, 917, 937,
      906, 947, 936, 947, 906, 870, 901, 940, 925, 894, 893, 931, 948, 959, 929, 878, 840, 868, 913, 894, 887, 883, 895, 899,
      1074, 1078, 1000, 1054, 972, 910, 940, 952, 952, 982, 954, 866, 1172, 1034, 990, 1132, 1088, 950, 900, 960, 988, 954, 886, 852,
      1150, 1060, 1136, 1208, 1132, 1016, 954, 930, 950, 928, 838, 782, 1032, 1034, 1202, 1228, 1174, 1094, 1028, 984, 888, 804, 796, 822,
      868, 880, 1116, 1230, 1214, 1140, 1080, 1028, 874, 780, 772, 848, 812, 750, 948, 1136, 1158, 1110, 1066, 1020, 904, 854, 896, 870,
      796, 738, 878, 1052, 1102, 1060, 966, 918, 916, 912, 980, 1000, 838, 844, 954, 1042, 1016, 972, 910, 844, 890, 956, 1000, 964,
      866, 934, 1034, 1022, 1010, 902, 836, 868, 908, 954, 964, 994, 856, 1016, 1062, 1036, 994, 862, 840, 912, 958, 928, 936, 930,
      890, 972, 986, 996, 910, 840, 880, 954, 946, 894, 882, 936, 988, 996, 946, 856, 778, 824, 916, 906, 892, 886, 900, 902,
      1862, 2586, 3172, 3199, 3158, 2417, 1701, 2023, 1867, 1592, 1385, 1185, 2087, 3189, 3167, 3238, 3216, 3147, 3043, 2625, 2275, 1982, 1636, 1270,
      2050, 3202, 3240, 3276, -34, 3180, 3149, 3001, 2478, 2122, 1726, 1369, 1365, 3189, 3273, 14, -13, 3219, 3186, 3080, 2274, 1702, 1516, 1387,
      1016, 3112, -42, 15, 3279, 3242, 3212, 2825, 1605, 1013, 994, 1115, 1073, 1380, 3146, -32, 3251, 3227, 3205, 1980, 954, 515, 518, 694,
      379, -231, 1880, 3198, 3223, 3202, 1602, 631, 262, 129, 210, 295, -181, -178, -10, 1880, 2349, 1817, 1093, 495, 125, 5, -3, -76,
      -167, -133, -80, 724, 1125, 1380, 1489, 1363, 1065, 735, 408, 141, -172, -92, 173, 735, 1055, 1147, 1280, 1580, 1738, 1567, 1235, 798,
      -155, -114, 391, 863, 977, 973, 1088, 1364, 1629, 1690, 1643, 1469, -106, -25, 640, 838, 803, 910, 1074, 1166, 1288, 1428, 1549, 1598,
      2650, 4094, 5344, 5344, 5344, 3924, 2462, 3094, 2782, 2202, 1816, 1504, 3002, 5344, 5344, 5344, 5344, 5344, 5186, 4290, 3562, 3010, 2386, 1688,
      2950, 5344, 5344, 5344, -1200, 5344, 5344, 5072, 4006, 3316, 2614, 1956, 1698, 5344, 5344, -1200, -1200, 5344, 5344, 5176, 3660, 2600, 2236, 1952,
      1164, 5344, -1200, -1200, 5344, 5344, 5344, 4622, 2336, 1246, 1216, 1382, 1334, 2010, 5344, -1200, 5344, 5344, 5344, 2940, 1004, 176, 140, 518,
      -38, -1200, 2882, 5344, 5344, 5344, 2238, 344, -392, -654, -560, -410, -1200, -1200, -974, 2718, 3682, 2662, 1276, 146, -640, -946, -1006, -1116,
      -1200, -1200, -1194, 426, 1240, 1858, 2142, 1858, 1222, 516, -148, -712, -1200, -1200, -716, 434, 1116, 1432, 1720, 2248, 2518, 2206, 1534, 666,
      -1200, -1200, -204, 730, 1044, 1106, 1296, 1774, 2312, 2486, 2404, 2002, -1200, -1046, 334, 820, 828, 996, 1232, 1426, 1684, 1970, 2198, 2294,
      3997, 4719, 2072, 2072, 4647, 4634, 3903, 2961, 791, 501, 3580, 3424, 4173, 2072, 2072, 2260, 2267, 4898, 5265, 3496, 1181, 905, 3865, 3516,
      3001, 2072, 2072, 2072, -1200, 2072, 2072, 1936, 1403, 4330, 3979, 3650, 249, 5344, 3630, -1200, 2072, 5344, 2072, 1988, 4502, 3972, 3452, 1957,
      -18, 5344, 2072, 2072, 2072, 2072, 2072, 1711, 3840, 3295, 1853, 673, 1737, 3677, 5344, -638, 2072, 5344, 2072, 4142, 3174, 2760, 2152, 1252,
      -101, -1021, 841, 5344, 5344, 2072, 3741, -428, -149, 1143, 1726, 1740, -1200, -1200, 521, 4031, 4513, 4003, 38, -527, -920, -1073, -1103, -320,
      -1200, -1200, -1197, -387, 1174, 3601, 3743, 1484, 11, -342, -674, -956, -1200, -1200, -958, -383, 1380, 3158, 3532, 3650, 3017, 2174, 917, -267,
      -1200, -1200, -702, 202, 1805, 2542, 3016, 3207, 3327, 3284, 3155, 2386, -1200, -1123, -433, 1270, 1663, 2084, 2623, 2798, 2831, 2729, 2760, 2999,
      5344, 5344, -1200, -1200, 3950, 5344, 5344, 2828, -1200, -1200, 5344, 5344, 5344, -1200, -1200, -824, -810, 4452, 5344, 2702, -1200, -1200, 5344, 5344,
      3052, -1200, -1200, -1200, -1200, -1200, -1200, -1200, -1200, 5344, 5344, 5344, -1200, 5344, 1916, -1200, 5344, 5344, -1200, -1200, 5344, 5344, 4668, 1962,
      -1200, 5344, 5344, 5344, -1200, -1200, -1200, -1200, 5344, 5344, 2490, -36, 2140, 5344, 5344, -76, -1200, 5344, -1200, 5344, 5344, 5344, 4164, 1986,
      -164, -842, -1200, 5344, 5344, -1200, 5244, -1200, 94, 2940, 4012, 3890, -1200, -1200, 2016, 5344, 5344, 5344, -1200, -1200, -1200, -1200, -1200, 476,
      -1200, -1200, -1200, -1200, 1108, 5344, 5344, 1110, -1200, -1200, -1200, -1200, -1200, -1200, -1200, -1200, 1644, 4884, 5344, 5052, 3516, 2142, 300, -1200,
      -1200, -1200, -1200, -326, 2566, 3978, 4736, 4640, 4342, 4082, 3906, 2770, -1200, -1200, -1200, 1720, 2498, 3172, 4014, 4170, 3978, 3488, 3322, 3704,
      5344, 5344, 2072, 1085, 4392, 5344, 5344, 4086, 2072, 1466, 4216, 3969, 5344, -1200, -1200, 2260, 2267, 4898, 5344, 4023, 1175, 624, 3708, 3638,
      926, 556, -1200, 2072, 399, 546, 1244, 876, 459, 3727, 3507, 3180, -1200, 5344, 358, 2072, 3556, 3912, 1511, 1350, 3980, 3680, 2998, 1403,
      2072, 3908, 5344, 2072, 2072, 2072, 2072, 2072, 4370, 3501, 1697, 301, 470, 5344, 5344, 2634, -1200, 5344, 2072, 5144, 4234, 3733, 2814, 1481,
      -682, 642, -1200, 2439, 2072, 2072, 3059, -1200, -320, 1887, 2760, 2704, -1200, -1192, 3680, 5344, 5344, 5344, -1200, -1200, -1200, -1200, -1200, 240,
      -1200, -1200, -214, 799, 3226, 5344, 4029, 88, -1200, -1200, -1200, -1200, -1200, -1200, -646, 233, 2558, 4730, 4790, 3702, 2082, 898, -306, -1142,
      -1200, -1200, -351, 917, 2716, 3555, 4062, 3790, 3151, 2651, 2283, 1436, -1200, -1200, 136, 2077, 2335, 2701, 3322, 3422, 3136, 2558, 2195, 2277,
      5344, 5344, 5344, 3370, 4834, 5344, 5344, 5344, 5344, 4132, 3088, 2594, 5344, -1200, -1200, 5344, 5344, 5344, 5344, 5344, 3550, 2448, 2072, 1932,
      -1200, 2312, -1200, 5344, 1998, 2292, 3688, 2952, 2118, 2110, 1670, 1016, -1200, 5344, -1200, 5344, 1768, 2480, 4222, 3900, 2616, 2016, 1328, 844,
      5344, 2472, 5344, -1200, 5344, 5344, 5344, 5344, 3396, 1658, 904, 638, -1200, 5344, 5344, 5344, -1200, 5344, 5344, 4944, 3124, 2122, 1464, 976,
      -1200, 2126, -1200, -466, -1200, 5344, 874, -1200, -734, 834, 1508, 1518, -1200, -1184, 5344, 5344, 5344, 5344, -1200, -1200, -1200, -1200, -1200, 4,
      -1200, -1200, 772, 2798, 5344, 5344, 2714, -934, -1200, -1200, -1200, -1200, -1200, -1200, -92, 1666, 3472, 4576, 4236, 2352, 648, -346, -912, -1084,
      -1200, -1200, 498, 2160, 2866, 3132, 3388, 2940, 1960, 1220, 660, 102, -1200, -1200, 1472, 2434, 2172, 2230, 2630, 2674, 2294, 1628, 1068, 850,
      5344, 5344, 5344, 1085, 1817, 3553, 4553, 4857, 4986, 4194, 3326, 2975, 2072, -1200, 741, 5344, 3603, 4045, 4314, 4618, 3625, 2461, 1845, 2030,
      2072, 3828, 2072, 5344, 3671, 3239, 3321, 2826, 2373, 2053, 1410, 803, -1200, 5344, -1200, 5344, 3556, 3912, 3880, 3026, 2324, 2015, 1541, 1027,
      2932, 3908, 5344, 2072, 5344, 5312, 4345, 3239, 1983, 1276, 1130, 1146, -1200, 4239, 5344, 5344, 2072, 5344, 4546, 3041, 1471, 907, 688, 714,
      -1200, 1745, 1181, 2439, 2072, 5344, 2329, 303, -25, 442, 564, 452, -879, -230, 3362, 4082, 4551, 4529, 757, 392, 216, -2, -213, 164,
      -527, -268, 835, 2091, 3520, 3582, 2297, 397, 250, 184, 140, 75, -270, -206, 398, 1373, 2382, 2946, 2905, 1973, 1081, 520, 237, 151,
      -163, -174, 725, 1590, 2001, 2148, 2366, 2221, 1712, 1315, 947, 640, -135, -123, 1221, 1672, 1566, 1684, 1902, 2005, 1854, 1504, 1149, 971,
      5344, 5344, 5344, -1200, -1200, 1762, 3762, 4370, 4628, 4256, 3564, 3356, -1200, -1200, 2682, 5344, 1862, 2746, 3284, 3892, 3700, 2474, 1618, 2128,
      5344, 5344, 5344, 5344, 5344, 4186, 2954, 2700, 2628, 1996, 1150, 590, -1200, 5344, -1200, 5344, 5344, 5344, 3538, 2152, 2032, 2014, 1754, 1210,
      520, 5344, 5344, 5344, 5344, 5280, 3346, 1134, 570, 894, 1356, 1654, -1200, 3134, 5344, 5344, 5344, 5344, 3748, 1138, -182, -308, -88, 452,
      -1200, 1364, 3562, 5344, 5344, 5344, 3784, 1806, 684, 50, -380, -614, -558, 724, 1380, 2820, 3758, 3714, 2714, 1984, 1632, 1196, 774, 324,
      146, 664, 898, 1384, 1696, 1820, 1880, 1728, 1700, 1568, 1480, 1350, 660, 788, 888, 1080, 1292, 1316, 1574, 1594, 1514, 1386, 1386, 1386,
      874, 852, 952, 1020, 1136, 1164, 1344, 1502, 1464, 1410, 1234, 1178, 930, 954, 970, 910, 960, 1138, 1174, 1336, 1414, 1380, 1230, 1092,
      3126, 3139, 2821, -345, 489, 2988, 4415, 4797, 4832, 4133, 3270, 3042, 656, 1478, 2893, 3621, 2002, 2925, 3631, 4267, 4163, 3071, 2055, 1939,
      4702, 5344, 5344, 4534, 4139, 3435, 2919, 3126, 3145, 2449, 1527, 812, 1063, 5344, 2072, 5016, 4698, 4256, 3074, 2520, 2506, 2168, 1619, 1079,
      1509, 5063, 5170, 5044, 5068, 4664, 3095, 1866, 1473, 1299, 1278, 1349, 340, 3462, 4920, 5036, 5183, 4945, 3408, 1691, 742, 455, 480, 749,
      98, 1863, 3531, 4930, 5127, 4860, 3338, 1830, 942, 530, 326, 193, 513, 1243, 1862, 3093, 3807, 3555, 2513, 1720, 1332, 1086, 887, 674,
      977, 1149, 1318, 1765, 2069, 2100, 1870, 1474, 1331, 1238, 1183, 1148, 1265, 1200, 1228, 1391, 1656, 1743, 1627, 1378, 1244, 1150, 1126, 1130,
      1340, 1191, 1179, 1269, 1556, 1603, 1432, 1297, 1224, 1184, 1058, 992, 1339, 1316, 1199, 1162, 1402, 1494, 1242, 1181, 1182, 1169, 1079, 969,
  };
  Volume v = voxels(14, {});
  std::fill(v.values.begin(), v.values.end(), -1200.0f);
  for (Index z = 0; z < 12; ++z)
    for (Index y = 0; y < 12; ++y)
      for (Index x = 0; x < 12; ++x) v.at(x + 1, y + 1, z + 1) = static_cast<float>(values[x + 12 * (y + 12 * z)]);
  const Meshed m = mesh_of(v);
  expect_closed_manifold(m);
  const ExtractReport& r = m.result.report;
  EXPECT_EQ(r.forced_points, 0u);
  EXPECT_EQ(r.relocated_points, 2u);
  EXPECT_EQ(m.check.num_boundary_components, 1u);
  EXPECT_EQ(m.check.euler_characteristic, -26);
  std::vector<std::uint8_t> before(v.values.size());
  for (std::size_t i = 0; i < before.size(); ++i) before[i] = v.values[i] > 0.5f;
  EXPECT_EQ(digital_topology(repaired_flags(v, r, false), 14), digital_topology(before, 14));
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
  // A sample at the isovalue on the solid's outer surface is not a cavity; the 4 cells inward
  // of it would put their vertices on it, so it is made inside (a simple flip, zero_level).
  {
    Volume v = block_with_cavities({});
    v.at(1, 3, 3) = 0.5f;
    const Meshed m = mesh_of(v);
    expect_closed_manifold(m);
    EXPECT_EQ(m.result.report.degenerate_components, 0u);
    EXPECT_EQ(m.result.report.zero_level_points, 1u);
    EXPECT_EQ(m.result.mesh.num_hexes(), 6 * 6 * 6);
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
    EXPECT_EQ(r.simple_points + r.relocated_points + r.forced_points + r.degenerate_points + r.zero_level_points, r.edits.size());
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
