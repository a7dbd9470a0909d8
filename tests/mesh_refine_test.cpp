// Conforming 3-refinement (mesh/refine.hpp): every template under every cube symmetry, random
// marks on generated meshes, uniform refinement, the CLI.
#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/generate.hpp"
#include "isohex/mesh/refine.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/mesh/validate.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <set>

using namespace isohex;
using isohex::test::run_cli;
using isohex::test::scratch_dir;
constexpr auto q = isohex::test::quote;

namespace {

using P3 = std::array<int, 3>;
using PointSet = std::array<P3, 4>;  // a quad as its sorted lattice points

constexpr std::array<P3, 8> kBits = {{{0, 0, 0}, {6, 0, 0}, {6, 6, 0}, {0, 6, 0},
                                      {0, 0, 6}, {6, 0, 6}, {6, 6, 6}, {0, 6, 6}}};

PointSet sorted4(std::array<P3, 4> p) {
  std::sort(p.begin(), p.end());
  return p;
}

/// The expected subdivision of a parent face from its marks alone, written independently of
/// the library: in face coordinates (u, v) in sixths with the face's corners rotated so that
/// the marked ones come first.
std::set<PointSet> expected_face(const std::array<int, 4>& face, std::uint8_t mask) {
  std::array<int, 4> c = face;
  const auto marked = [&](int k) { return (mask >> c[k] & 1) != 0; };
  int n = 0;
  for (int k = 0; k < 4; ++k) n += marked(k);
  for (int r = 0; r < 4 && n > 0 && n < 4; ++r) {
    if (marked(0) && (n == 1 || marked(1))) break;
    std::rotate(c.begin(), c.begin() + 1, c.end());
  }
  auto at = [&](int u, int v) {
    P3 p;
    for (int a = 0; a < 3; ++a)
      p[a] = kBits[c[0]][a] + (u * (kBits[c[1]][a] - kBits[c[0]][a]) + v * (kBits[c[3]][a] - kBits[c[0]][a])) / 6;
    return p;
  };
  std::vector<std::array<std::array<int, 2>, 4>> quads;
  auto square = [&](int u, int v) { quads.push_back({{{u, v}, {u + 2, v}, {u + 2, v + 2}, {u, v + 2}}}); };
  if (n == 0) quads.push_back({{{0, 0}, {6, 0}, {6, 6}, {0, 6}}});
  if (n == 1) {
    square(0, 0);
    quads.push_back({{{2, 0}, {6, 0}, {6, 6}, {2, 2}}});
    quads.push_back({{{0, 2}, {2, 2}, {6, 6}, {0, 6}}});
  }
  if (n == 2) {
    for (int i = 0; i < 3; ++i) square(2 * i, 0);
    quads.push_back({{{0, 2}, {2, 2}, {2, 4}, {0, 6}}});
    quads.push_back({{{2, 2}, {4, 2}, {4, 4}, {2, 4}}});
    quads.push_back({{{4, 2}, {6, 2}, {6, 6}, {4, 4}}});
    quads.push_back({{{2, 4}, {4, 4}, {6, 6}, {0, 6}}});
  }
  if (n == 4)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) square(2 * i, 2 * j);
  std::set<PointSet> s;
  for (const auto& qd : quads) s.insert(sorted4({at(qd[0][0], qd[0][1]), at(qd[1][0], qd[1][1]),
                                                 at(qd[2][0], qd[2][1]), at(qd[3][0], qd[3][1])}));
  return s;
}

struct TemplateCheck {
  double volume = 0, min_sj = 2;
};

/// Checks one lattice template for the configuration `mask` on the unit cube: positive
/// orientation, volumes summing to 1, each parent face showing its pattern, interior faces
/// shared by exactly two sub-hexes, and a valid mesh.
TemplateCheck check_template(const std::vector<LatticeHex>& t, std::uint8_t mask) {
  TemplateCheck r;
  HexMesh m;
  std::map<P3, Index> ids;
  std::map<PointSet, int> faces;
  for (const LatticeHex& lh : t) {
    std::array<Vec3, 8> p;
    Hex h;
    for (int c = 0; c < 8; ++c) {
      p[c] = Vec3(lh[c][0], lh[c][1], lh[c][2]) / 6.0;
      auto [it, fresh] = ids.try_emplace(lh[c], static_cast<Index>(m.points.size()));
      if (fresh) m.points.push_back(p[c]);
      h[c] = it->second;
    }
    m.hexes.push_back(h);
    r.volume += volume(p);
    r.min_sj = std::min(r.min_sj, scaled_jacobian(p));
    for (const auto& f : kHexFaces) ++faces[sorted4({lh[f[0]], lh[f[1]], lh[f[2]], lh[f[3]]})];
  }
  for (int f = 0; f < 6; ++f) {
    // The parent face is the plane where one coordinate is constant over its corners.
    int axis = -1;
    for (int a = 0; a < 3; ++a) {
      bool same = true;
      for (int k : kHexFaces[f]) same = same && kBits[k][a] == kBits[kHexFaces[f][0]][a];
      if (same) axis = a;
    }
    const int value = kBits[kHexFaces[f][0]][axis];
    std::set<PointSet> got;
    for (const auto& [fs, count] : faces)
      if (std::all_of(fs.begin(), fs.end(), [&](const P3& p) { return p[axis] == value; })) {
        got.insert(fs);
        EXPECT_EQ(count, 1) << "boundary quad used twice, mask " << int(mask);
      }
    EXPECT_EQ(got, expected_face(kHexFaces[f], mask)) << "face " << f << ", mask " << int(mask);
  }
  for (const auto& [fs, count] : faces) {
    const bool on_boundary = [&] {
      for (int a = 0; a < 3; ++a)
        for (int value : {0, 6})
          if (std::all_of(fs.begin(), fs.end(), [&](const P3& p) { return p[a] == value; })) return true;
      return false;
    }();
    if (!on_boundary) {
      EXPECT_EQ(count, 2) << "interior quad not shared by two sub-hexes, mask " << int(mask);
    }
  }
  EXPECT_TRUE(validate(m).valid()) << "mask " << int(mask);
  return r;
}

/// The 48 symmetries of the cube as maps of sixths, with whether each reflects.
struct Sym {
  std::array<int, 3> perm;
  std::array<bool, 3> flip;
  P3 operator()(const P3& p) const {
    P3 r;
    for (int i = 0; i < 3; ++i) r[i] = flip[i] ? 6 - p[perm[i]] : p[perm[i]];
    return r;
  }
  bool reflects() const {
    const Eigen::Matrix3d m = [&] {
      Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
      for (int i = 0; i < 3; ++i) a(i, perm[i]) = flip[i] ? -1 : 1;
      return a;
    }();
    return m.determinant() < 0;
  }
};
std::vector<Sym> symmetries() {
  std::vector<Sym> s;
  std::array<int, 3> perm = {0, 1, 2};
  do
    for (int f = 0; f < 8; ++f) s.push_back({perm, {(f & 1) != 0, (f & 2) != 0, (f & 4) != 0}});
  while (std::next_permutation(perm.begin(), perm.end()));
  return s;
}

std::set<std::array<P3, 8>> as_point_sets(const std::vector<LatticeHex>& t) {
  std::set<std::array<P3, 8>> s;
  for (LatticeHex h : t) {
    std::sort(h.begin(), h.end());
    s.insert(h);
  }
  return s;
}

double total_volume(const HexMesh& m) {
  double v = 0;
  for (Index h = 0; h < m.num_hexes(); ++h) v += volume(m.corners(h));
  return v;
}

double boundary_area(const HexMesh& m) {
  double a = 0;
  for (const Quad& qd : boundary_quads(m)) {
    const Vec3 &p0 = m.points[qd[0]], &p1 = m.points[qd[1]], &p2 = m.points[qd[2]], &p3 = m.points[qd[3]];
    a += 0.5 * ((p1 - p0).cross(p2 - p0).norm() + (p2 - p0).cross(p3 - p0).norm());
  }
  return a;
}

}  // namespace

TEST(Refine, TemplatesUnderAllCubeSymmetries) {
  const std::array<std::pair<std::uint8_t, int>, 4> canonical = {{{0x01, 4}, {0x03, 11}, {0x0f, 22}, {0xff, 27}}};
  const std::vector<Sym> syms = symmetries();
  ASSERT_EQ(syms.size(), 48u);
  for (const auto& [mask, count] : canonical) {
    const std::vector<LatticeHex>& t = template_hexes(mask);
    ASSERT_EQ(static_cast<int>(t.size()), count);
    const TemplateCheck c = check_template(t, mask);
    EXPECT_NEAR(c.volume, 1.0, 1e-14);
    std::printf("template %-6s: %2d hexes, min scaled Jacobian %.4f\n", refine_template_name(template_of(mask)), count,
                c.min_sj);
    EXPECT_GT(c.min_sj, 0.3);
    for (const Sym& s : syms) {
      std::uint8_t image = 0;  // the marks the symmetry takes the canonical ones to
      for (int k = 0; k < 8; ++k)
        if (mask >> k & 1)
          for (int j = 0; j < 8; ++j)
            if (s(kBits[k]) == kBits[j]) image |= static_cast<std::uint8_t>(1u << j);
      std::vector<LatticeHex> mapped;
      for (const LatticeHex& h : t) {
        LatticeHex m;
        for (int k = 0; k < 8; ++k) m[k] = s(h[k]);
        if (s.reflects()) m = {m[0], m[3], m[2], m[1], m[4], m[7], m[6], m[5]};
        mapped.push_back(m);
      }
      const TemplateCheck cm = check_template(mapped, image);
      EXPECT_NEAR(cm.volume, 1.0, 1e-14);
      EXPECT_NEAR(cm.min_sj, c.min_sj, 1e-12);
      // The library's template for these marks is the same decomposition up to symmetry of
      // the template itself: same hex count, same face patterns (checked), same quality.
      const std::vector<LatticeHex>& lib = template_hexes(image);
      EXPECT_EQ(lib.size(), t.size());
      const TemplateCheck cl = check_template(lib, image);
      EXPECT_NEAR(cl.min_sj, c.min_sj, 1e-12);
      if (mask != 0x0f) {  // these templates are symmetric; the face template is not (x <-> y)
        EXPECT_EQ(as_point_sets(lib), as_point_sets(mapped));
      }
    }
  }
}

TEST(Refine, PromotionRules) {
  int valid = 0;
  for (int m = 0; m < 256; ++m) {
    const auto mask = static_cast<std::uint8_t>(m);
    const std::uint8_t p = promoted_mask(mask);
    EXPECT_EQ(p & mask, mask);
    EXPECT_EQ(promoted_mask(p), p);
    valid += p == mask;
  }
  EXPECT_EQ(valid, 1 + 8 + 12 + 6 + 1);  // none, corners, edges, faces, all
  EXPECT_EQ(promoted_mask(0x05), 0x0f);  // face diagonal -> face
  EXPECT_EQ(promoted_mask(0x41), 0xff);  // body diagonal -> all
  EXPECT_EQ(promoted_mask(0x07), 0x0f);  // three on a face -> face
  EXPECT_EQ(promoted_mask(0x13), 0x33);  // three on a side face -> that face
  EXPECT_EQ(promoted_mask(0x15), 0xff);  // three not on a face -> all
}

TEST(Refine, RandomMarksOnGeneratedMeshes) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 24; ++trial) {
    const int kind = trial % 3;  // box, jittered box, ball
    HexMesh m = kind == 2 ? ball_mesh(3) : box_mesh(4, 3, 5, Vec3(-1, 0, 0), Vec3(2, 1.5, 2.5));
    if (kind == 1) jitter(m, 0.08, 11 + trial);
    m.blocks.resize(m.hexes.size());
    for (Index h = 0; h < m.num_hexes(); ++h) m.blocks[h] = h % 3;
    const double p = 0.02 + 0.04 * (trial % 4);
    std::vector<std::uint8_t> marks(m.points.size());
    for (auto& f : marks) f = std::uniform_real_distribution<double>(0, 1)(rng) < p;
    const RefineResult r = refine(m, marks);
    const ValidationReport v = validate(r.mesh);
    ASSERT_TRUE(v.valid()) << "trial " << trial;
    EXPECT_EQ(v.count(FaultKind::unused_vertex), 0u);
    EXPECT_EQ(v.euler_characteristic, validate(m).euler_characteristic);
    ASSERT_EQ(r.parent_hex.size(), r.mesh.hexes.size());
    for (std::size_t h = 0; h < r.parent_hex.size(); ++h) ASSERT_EQ(r.mesh.blocks[h], m.blocks[r.parent_hex[h]]);
    std::size_t children = 0;
    for (std::size_t c : r.children) children += c;
    EXPECT_EQ(children, r.mesh.hexes.size());
    // Every hex's final marks form a template configuration.
    for (const Hex& h : m.hexes) {
      std::uint8_t mask = 0;
      for (int c = 0; c < 8; ++c) mask |= static_cast<std::uint8_t>(r.marked[h[c]] << c);
      EXPECT_EQ(promoted_mask(mask), mask);
    }
    if (kind == 0) {
      EXPECT_NEAR(total_volume(r.mesh), total_volume(m), 1e-12);
      const auto sj = scaled_jacobians(r.mesh);
      EXPECT_GT(*std::min_element(sj.begin(), sj.end()), 0.0);  // none inverted
    }
    // Boundary quads of the result cover the original boundary: the same area where it is
    // planar, within the bilinear-patch approximation where it is not.
    const double area = boundary_area(m);
    EXPECT_NEAR(boundary_area(r.mesh), area, kind == 0 ? 1e-12 : 0.02 * area);
    // Sources: 2, 4 or 8 input vertices, ascending, whose box holds the new vertex; a new
    // boundary vertex comes from an input edge or quad of boundary vertices.
    const auto n_in = static_cast<std::size_t>(m.num_vertices());
    ASSERT_EQ(r.source_offsets.size(), r.mesh.points.size() - n_in + 1);
    const std::vector<std::uint8_t> in_boundary = boundary_vertex_mask(m), out_boundary = boundary_vertex_mask(r.mesh);
    for (std::size_t v = n_in; v < r.mesh.points.size(); ++v) {
      const auto* b = r.source_ids.data() + r.source_offsets[v - n_in];
      const auto* e = r.source_ids.data() + r.source_offsets[v - n_in + 1];
      const auto n = e - b;
      ASSERT_TRUE(n == 2 || n == 4 || n == 8) << n;
      ASSERT_TRUE(std::is_sorted(b, e) && std::adjacent_find(b, e) == e);
      Eigen::AlignedBox3d box;
      for (auto* s = b; s != e; ++s) box.extend(m.points[*s]);
      EXPECT_TRUE(box.contains(r.mesh.points[v]) || box.exteriorDistance(r.mesh.points[v]) < 1e-12);
      if (out_boundary[v]) {
        EXPECT_LE(n, 4);
        for (auto* s = b; s != e; ++s) EXPECT_TRUE(in_boundary[*s]);
      }
    }
    // Deterministic.
    const RefineResult again = refine(m, marks);
    EXPECT_EQ(again.mesh.hexes, r.mesh.hexes);
    EXPECT_EQ(again.mesh.points, r.mesh.points);
  }
}

TEST(Refine, AllMarkedIsUniformSubdivision) {
  const HexMesh m = box_mesh(2, 3, 2);
  const RefineResult r = refine(m, std::vector<std::uint8_t>(m.points.size(), 1));
  EXPECT_EQ(r.parents[static_cast<int>(RefineTemplate::full)], 12u);
  EXPECT_EQ(r.promoted_vertices, 0u);
  const HexMesh fine = box_mesh(6, 9, 6);
  ASSERT_EQ(r.mesh.num_hexes(), fine.num_hexes());
  ASSERT_EQ(r.mesh.num_vertices(), fine.num_vertices());
  auto hex_keys = [](const HexMesh& mesh) {
    std::set<std::array<std::array<long, 3>, 8>> s;
    for (Index h = 0; h < mesh.num_hexes(); ++h) {
      std::array<std::array<long, 3>, 8> k;
      for (int c = 0; c < 8; ++c)
        for (int a = 0; a < 3; ++a) k[c][a] = std::lround(mesh.points[mesh.hexes[h][c]][a] * 1e9);
      s.insert(k);  // VTK order kept: same orientation and same first corner
    }
    return s;
  };
  EXPECT_EQ(hex_keys(r.mesh), hex_keys(fine));
}

TEST(Refine, OneMarkedVertexAndFixedFlags) {
  HexMesh m = box_mesh(2, 2, 2);
  m.fixed.assign(m.points.size(), 0);
  for (Index v = 0; v < m.num_vertices(); ++v) m.fixed[v] = m.points[v].z() == 0;  // the bottom is held
  std::vector<std::uint8_t> marks(m.points.size(), 0);
  marks[4] = 1;  // the centre of the bottom face: vertex (1, 1, 0) of the 3 x 3 x 3 lattice
  const RefineResult r = refine(m, marks);
  ASSERT_TRUE(validate(r.mesh).valid());
  EXPECT_EQ(r.promoted_vertices, 0u);
  EXPECT_EQ(r.parents[static_cast<int>(RefineTemplate::corner)], 4u);  // the four hexes at vertex 4
  for (Index v = m.num_vertices(); v < r.mesh.num_vertices(); ++v)
    EXPECT_EQ(r.mesh.fixed[v] != 0, r.mesh.points[v].z() == 0) << v;
  EXPECT_THROW(refine(m, std::vector<std::uint8_t>(3, 1)), Error);
  EXPECT_THROW(marked_vertices_of(m, {8}), Error);
}

TEST(RefineCli, RegionIdsAndErrors) {
  const auto dir = scratch_dir();
  std::string out;
  ASSERT_EQ(run_cli("generate box -n 4 --size 4 -o " + q(dir / "box.vtu"), &out), 0) << out;
  ASSERT_EQ(run_cli("refine " + q(dir / "box.vtu") + " -o " + q(dir / "r.vtu") +
                        " --hexes 'region:sphere(0,0,0,1.6)' --json " + q(dir / "r.json"),
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("min scaled Jacobian: 1.0000 before"), std::string::npos) << out;
  const auto j = nlohmann::json::parse(io::read_file(dir / "r.json"));
  const HexMesh r = io::read_mesh(dir / "r.vtu");
  EXPECT_TRUE(validate(r).valid());
  EXPECT_EQ(j["hexes_after"], r.num_hexes());
  EXPECT_GT(j["templates"]["full"]["parents"].get<int>(), 0);
  EXPECT_GT(j["min_scaled_jacobian_after"].get<double>(), 0.3);
  {
    std::ofstream f(dir / "ids.txt");
    f << "0\n";
  }
  ASSERT_EQ(run_cli("refine " + q(dir / "box.vtu") + " -o " + q(dir / "i.vtu") + " --hexes ids:" + q(dir / "ids.txt"),
                    &out),
            0)
      << out;
  EXPECT_NE(out.find("marked vertices: 8; promoted: 0"), std::string::npos) << out;
  {
    std::ofstream f(dir / "bad.txt");
    f << "64\n";
  }
  EXPECT_EQ(run_cli("refine " + q(dir / "box.vtu") + " -o " + q(dir / "x.vtu") + " --hexes ids:" + q(dir / "bad.txt"),
                    &out),
            2);
  EXPECT_NE(out.find("line 1: hex id 64 is out of range [0, 64)"), std::string::npos) << out;
  EXPECT_EQ(run_cli("refine " + q(dir / "box.vtu") + " -o " + q(dir / "x.vtu") + " --hexes 'region:sphere(9,9,9,0.1)'",
                    &out),
            2);
  EXPECT_NE(out.find("the selection is empty"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.vtu"));
  EXPECT_EQ(run_cli("refine --help", &out), 0);
}

// close_marks: the same least fixpoint as refine()'s promotion; over its limit it leaves the
// marks as they were, seeds aside.
TEST(Refine, CloseMarksRespectsItsLimit) {
  const HexMesh m = box_mesh(3, 3, 3);
  const Incidence around = vertex_hexes(m);
  // Two diagonal corners of the middle hex: no template, so its 8 corners are marked, and
  // from there its neighbours' too.
  const Hex& mid = m.hexes[13];
  std::vector<std::uint8_t> marks(m.points.size(), 0);
  marks[mid[0]] = marks[mid[6]] = 1;
  std::vector<std::uint8_t> limited = marks;
  EXPECT_EQ(close_marks(m, around, limited, {mid[0], mid[6]}, 3), 4u);
  EXPECT_EQ(limited, marks);
  std::vector<std::uint8_t> closed = marks;
  const std::size_t added = close_marks(m, around, closed, {mid[0], mid[6]});
  EXPECT_GE(added, 6u);
  const RefineResult r = refine(m, marks);
  EXPECT_EQ(r.marked, closed);
  EXPECT_EQ(r.promoted_vertices, added);
}
