// Mesh core: topology counts and validation faults on constructed meshes.
#include "isohex/mesh/topology.hpp"
#include "isohex/mesh/validate.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <random>
#include <set>

using namespace isohex;
using isohex::test::grid_mesh;

namespace {

// A unit cube hex placed with its low corner at (x, y, z), with its own 8 vertices.
Index add_cube(HexMesh& m, double x, double y, double z) {
  const Index b = m.num_vertices();
  const double c[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (auto& p : c) m.points.emplace_back(x + p[0], y + p[1], z + p[2]);
  m.hexes.push_back({b, b + 1, b + 2, b + 3, b + 4, b + 5, b + 6, b + 7});
  return m.num_hexes() - 1;
}

// Merges coincident vertices (exact coordinates) so that touching cubes share vertices.
void weld(HexMesh& m) {
  std::map<std::array<double, 3>, Index> seen;
  std::vector<Index> remap(m.points.size());
  std::vector<Vec3> pts;
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    auto key = std::array<double, 3>{m.points[i].x(), m.points[i].y(), m.points[i].z()};
    auto [it, fresh] = seen.emplace(key, static_cast<Index>(pts.size()));
    if (fresh) pts.push_back(m.points[i]);
    remap[i] = it->second;
  }
  for (Hex& h : m.hexes)
    for (Index& v : h) v = remap[v];
  m.points = pts;
}

}  // namespace

TEST(Topology, GridCounts) {
  const int nx = 3, ny = 4, nz = 5;
  HexMesh m = grid_mesh(nx, ny, nz);
  const auto quads = build_quads(m);
  EXPECT_EQ(quads.size(), std::size_t((nx + 1) * ny * nz + nx * (ny + 1) * nz + nx * ny * (nz + 1)));
  EXPECT_EQ(boundary_quads(m).size(), std::size_t(2 * (nx * ny + ny * nz + nx * nz)));
  EXPECT_EQ(build_edges(m).size(),
            std::size_t(nx * (ny + 1) * (nz + 1) + (nx + 1) * ny * (nz + 1) + (nx + 1) * (ny + 1) * nz));
  const Incidence inc = vertex_hexes(m);
  EXPECT_EQ(inc.count(0), 1u);  // a corner of the box
  const Index centre = 1 + (nx + 1) * (1 + (ny + 1) * 1);
  EXPECT_EQ(inc.count(centre), 8u);
}

// build_quads() and boundary_quads() gather the faces vertex by vertex; their order must be
// that of a sort of every face's key (sorted vertex ids, then hex × 6 + face), the order the
// numberings downstream (pillow hexes, surface graphs) are made from. The oracle here sorts
// every key, on a jittered, renumbered grid with a repeated-vertex (collapsed) hex and a quad
// shared by three hexes; 2,145 vertices, so that the scans' blocks of vertices are several.
TEST(Topology, QuadsInTheOrderOfTheirSortedKeys) {
  HexMesh m = grid_mesh(14, 12, 10);
  std::mt19937 rng(5);
  std::vector<Index> perm(m.points.size());
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  for (Hex& h : m.hexes)
    for (Index& v : h) v = perm[v];
  std::vector<Vec3> moved(m.points.size());
  for (std::size_t v = 0; v < perm.size(); ++v) moved[perm[v]] = m.points[v];
  m.points = moved;
  m.hexes.push_back(m.hexes[7]);         // a third hex on each face of hex 7
  m.hexes[3][6] = m.hexes[3][5];         // a collapsed edge: vertex repeated in one hex
  struct Key {
    std::array<Index, 4> key;
    Index hex_face;
    bool operator<(const Key& o) const { return key != o.key ? key < o.key : hex_face < o.hex_face; }
  };
  std::vector<Key> keys;
  for (Index h = 0; h < m.num_hexes(); ++h)
    for (int f = 0; f < 6; ++f) {
      Key k;
      for (int c = 0; c < 4; ++c) k.key[c] = m.hexes[h][kHexFaces[f][c]];
      std::sort(k.key.begin(), k.key.end());
      k.hex_face = h * 6 + f;
      keys.push_back(k);
    }
  std::sort(keys.begin(), keys.end());
  std::vector<std::pair<Index, Index>> expected;  // first hex's (hex, face), and the second hex or -1
  std::vector<Quad> expected_boundary;
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i + 1;
    while (j < keys.size() && keys[j].key == keys[i].key) ++j;
    expected.push_back({keys[i].hex_face, j - i > 1 ? keys[i + 1].hex_face / 6 : -1});
    if (j - i == 1) {
      const Hex& h = m.hexes[keys[i].hex_face / 6];
      const auto& f = kHexFaces[keys[i].hex_face % 6];
      expected_boundary.push_back({h[f[0]], h[f[1]], h[f[2]], h[f[3]]});
    }
    i = j;
  }
  const auto quads = build_quads(m);
  ASSERT_EQ(quads.size(), expected.size());
  for (std::size_t q = 0; q < quads.size(); ++q) {
    EXPECT_EQ(quads[q].hex[0] * 6 + quads[q].local[0], expected[q].first) << q;
    EXPECT_EQ(quads[q].hex[1], expected[q].second) << q;
  }
  EXPECT_EQ(boundary_quads(m), expected_boundary);
  EXPECT_EQ(boundary_quads(quads), expected_boundary);

  // face_neighbours(): the same pairs from the same sort, without the quads. Each face's first
  // two hexes see each other; a boundary face (and a third hex on a face) sees -1.
  const auto nb = face_neighbours(m);
  ASSERT_EQ(nb.size(), m.hexes.size());
  std::vector<std::array<Index, 6>> want(m.hexes.size());
  for (auto& w : want) w.fill(-1);
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i + 1;
    while (j < keys.size() && keys[j].key == keys[i].key) ++j;
    if (j - i > 1) {
      want[keys[i].hex_face / 6][keys[i].hex_face % 6] = keys[i + 1].hex_face / 6;
      want[keys[i + 1].hex_face / 6][keys[i + 1].hex_face % 6] = keys[i].hex_face / 6;
    }
    i = j;
  }
  EXPECT_EQ(nb, want);
}

TEST(Topology, BoundaryQuadsPointOutward) {
  HexMesh m = grid_mesh(2, 2, 2);
  const Vec3 centre(1, 1, 1);
  for (const Quad& q : boundary_quads(m)) {
    const Vec3 n = (m.points[q[2]] - m.points[q[0]]).cross(m.points[q[3]] - m.points[q[1]]);
    const Vec3 mid = 0.25 * (m.points[q[0]] + m.points[q[1]] + m.points[q[2]] + m.points[q[3]]);
    EXPECT_GT(n.dot(mid - centre), 0.0);
  }
}

TEST(Validate, GridIsValid) {
  HexMesh m = grid_mesh(3, 3, 3);
  const ValidationReport r = validate(m);
  EXPECT_TRUE(r.valid());
  EXPECT_EQ(r.num_warnings(), 0u);
  EXPECT_EQ(r.num_boundary_components, 1u);
  EXPECT_EQ(r.euler_characteristic, 2);
  EXPECT_EQ(r.num_boundary_quads, 54u);
}

TEST(Validate, CavityGivesTwoBoundaryComponents) {
  HexMesh m = grid_mesh(3, 3, 3);
  m.hexes.erase(m.hexes.begin() + 13);  // the centre hex
  const ValidationReport r = validate(m);
  EXPECT_TRUE(r.valid());
  EXPECT_EQ(r.num_boundary_components, 2u);
  EXPECT_EQ(r.euler_characteristic, 4);
}

TEST(Validate, TorusHasEulerZero) {
  HexMesh m = grid_mesh(3, 3, 1);
  m.hexes.erase(m.hexes.begin() + 4);  // through-hole
  const ValidationReport r = validate(m);
  EXPECT_TRUE(r.valid());
  EXPECT_EQ(r.euler_characteristic, 0);
}

TEST(Validate, CubesSharingAnEdgeAreNonManifold) {
  HexMesh m;
  add_cube(m, 0, 0, 0);
  add_cube(m, 1, 1, 0);
  weld(m);
  const ValidationReport r = validate(m);
  EXPECT_FALSE(r.valid());
  EXPECT_EQ(r.count(FaultKind::non_manifold_edge), 1u);
}

TEST(Validate, CubesSharingAVertexAreNonManifold) {
  HexMesh m;
  add_cube(m, 0, 0, 0);
  add_cube(m, 1, 1, 1);
  weld(m);
  const ValidationReport r = validate(m);
  EXPECT_FALSE(r.valid());
  EXPECT_EQ(r.count(FaultKind::non_manifold_edge), 0u);
  EXPECT_EQ(r.count(FaultKind::non_manifold_vertex), 1u);
  ASSERT_FALSE(r.faults.empty());
  EXPECT_NE(r.faults[0].message.find("non-manifold"), std::string::npos);
}

TEST(Validate, MirroredHexIsInconsistent) {
  HexMesh m = grid_mesh(2, 1, 1);
  Hex& h = m.hexes[1];
  std::swap(h[0], h[4]);  // mirror through the middle plane: swap bottom and top quads
  std::swap(h[1], h[5]);
  std::swap(h[2], h[6]);
  std::swap(h[3], h[7]);
  const ValidationReport r = validate(m);
  EXPECT_EQ(r.count(FaultKind::inconsistent_orientation), 1u);
  EXPECT_FALSE(r.valid());
}

TEST(Validate, QuadSharedByThreeHexes) {
  HexMesh m = grid_mesh(2, 1, 1);
  m.hexes.push_back(m.hexes[1]);  // a duplicate hex: every face shared 3 times around hex 0/1
  const ValidationReport r = validate(m);
  EXPECT_GE(r.count(FaultKind::quad_shared_by_many), 1u);
}

TEST(Validate, IdsOutOfRangeStopTopologyAndNameTheHex) {
  HexMesh m = grid_mesh(1, 1, 2);
  m.hexes[1][3] = 999;
  m.hexes[0][0] = -1;
  const ValidationReport r = validate(m);
  EXPECT_EQ(r.count(FaultKind::id_out_of_range), 2u);
  EXPECT_FALSE(r.topology_checked);
  std::set<std::string> messages;
  for (auto& f : r.faults) messages.insert(f.message);
  EXPECT_TRUE(messages.count("hex 1: vertex id 999 at corner 3 is out of range [0, 12)")) << *messages.begin();
}

TEST(Validate, RepeatedVertexAndNonFiniteAndUnused) {
  HexMesh m = grid_mesh(1, 1, 1);
  m.hexes[0][6] = m.hexes[0][2];
  m.points[1].y() = std::numeric_limits<double>::quiet_NaN();
  m.points.emplace_back(5, 5, 5);
  const ValidationReport r = validate(m);
  EXPECT_EQ(r.count(FaultKind::repeated_vertex), 1u);
  EXPECT_EQ(r.count(FaultKind::non_finite_coordinate), 1u);
  EXPECT_GE(r.count(FaultKind::unused_vertex), 1u);  // the new point and the dropped corner 6
  EXPECT_FALSE(r.valid());
}

TEST(Validate, UnusedVertexIsOnlyAWarning) {
  HexMesh m = grid_mesh(1, 1, 1);
  m.points.emplace_back(5, 5, 5);
  const ValidationReport r = validate(m);
  EXPECT_TRUE(r.valid());
  EXPECT_EQ(r.num_warnings(), 1u);
}

TEST(Validate, MessagesAreCappedButCountsAreNot) {
  HexMesh m = grid_mesh(10, 10, 1);
  for (auto& h : m.hexes) h[0] = 10000;
  ValidateOptions opt;
  opt.max_messages = 5;
  const ValidationReport r = validate(m, opt);
  EXPECT_EQ(r.count(FaultKind::id_out_of_range), 100u);
  EXPECT_EQ(r.faults.size(), 5u);
}
