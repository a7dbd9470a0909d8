// Cutting by sheet insertion: geometry against the analytic surfaces, conformity, quality,
// creases, errors, determinism.
#include "isohex/contour/iso_field.hpp"
#include "isohex/contour/region.hpp"
#include "isohex/error.hpp"
#include "isohex/mesh/generate.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/mesh/validate.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"
#include "isohex/sheets/csg_cuts.hpp"
#include "isohex/sheets/cut.hpp"
#include "test_support.hpp"

#include "isohex/io/atomic_file.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <oneapi/tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numbers>
#include <set>

namespace isohex::test {

namespace {

struct Ball {
  Vec3 c;
  double r;
  // Exact distance from p to the sphere (the oracle: not the shape code).
  [[nodiscard]] double distance(const Vec3& p) const { return std::abs((p - c).norm() - r); }
};

// The distance from p to the surface of the box [0, 2]^3.
double box_distance(const Vec3& p) {
  double d = std::numeric_limits<double>::infinity();
  for (int j = 0; j < 3; ++j) d = std::min({d, std::abs(p[j]), std::abs(p[j] - 2)});
  return d;
}

std::size_t below(const HexMesh& m, double level) {
  std::size_t n = 0;
  for (Index h = 0; h < m.num_hexes(); ++h) n += !(scaled_jacobian(m.corners(h)) >= level);
  return n;
}

double min_sj(const HexMesh& m) {
  double s = 1;
  for (Index h = 0; h < m.num_hexes(); ++h) s = std::min(s, scaled_jacobian(m.corners(h)));
  return s;
}

std::size_t not_certified(const HexMesh& m) {
  std::size_t n = 0;
  for (double c : certified_scaled_jacobians(m)) n += !(c > 0);
  return n;
}

Vec3 unit_normal(const HexMesh& m, const Quad& q) {
  return (m.points[q[2]] - m.points[q[0]]).cross(m.points[q[3]] - m.points[q[1]]).normalized();
}

// Per boundary edge (smaller id, larger id): the unit normals of its boundary quads.
std::map<std::pair<Index, Index>, std::vector<Vec3>> boundary_edge_normals(const HexMesh& m) {
  std::map<std::pair<Index, Index>, std::vector<Vec3>> out;
  for (const Quad& q : boundary_quads(m)) {
    const Vec3 qn = unit_normal(m, q);
    for (int i = 0; i < 4; ++i) out[{std::min(q[i], q[(i + 1) % 4]), std::max(q[i], q[(i + 1) % 4])}].push_back(qn);
  }
  return out;
}

// `isohex cut DIR/IN -o DIR/OUT ARGS --json ...`, expected to exit 0 (its output in `log`):
// the JSON report.
nlohmann::json cut_report(const std::filesystem::path& dir, const std::string& in, const std::string& out,
                          const std::string& args, std::string& log) {
  const auto json = dir / (out + ".json");
  EXPECT_EQ(run_cli("cut " + quote(dir / in) + " -o " + quote(dir / out) + " " + args + " --json " + quote(json), &log), 0)
      << log;
  return nlohmann::json::parse(io::read_file(json));
}

}  // namespace

// The paper's figures 6 and 7: a cube carved by three spheres that overlap each other and cross
// the cube's faces and edges.
TEST(Cut, CubeCarvedByThreeOverlappingSpheres) {
  const std::vector<Ball> balls{{{2, 2, 2}, 1.2}, {{2, 0.8, 1.0}, 0.75}, {{1.0, 2, 1.5}, 0.7}};
  std::vector<Shape> shapes;
  for (const Ball& b : balls) shapes.push_back(Shape::sphere(b.c, b.r));
  CutOptions opt;
  opt.keep = CutKeep::outside;
  const CutResult r = cut(box_mesh(12, 12, 12, Vec3::Zero(), Vec3(2, 2, 2)), shapes, opt);
  const HexMesh& m = r.mesh;
  ASSERT_EQ(r.steps.size(), 3u);
  EXPECT_TRUE(validate(m).valid());
  EXPECT_EQ(below(m, 0.2), 0u);
  EXPECT_GE(min_sj(m), 0.3);
  EXPECT_EQ(not_certified(m), 0u);
  // Every boundary vertex is on the cube's surface or on one of the spheres, and outside every
  // sphere; the curves: vertices on two surfaces.
  const double scale = 2 * std::sqrt(3.0);
  std::set<Index> on_boundary;
  for (const Quad& q : boundary_quads(m))
    for (Index v : q) on_boundary.insert(v);
  std::size_t curve = 0, on_sphere = 0;
  for (Index v : on_boundary) {
    const Vec3& p = m.points[v];
    int on = box_distance(p) <= 1e-9 * scale;
    for (const Ball& b : balls) {
      on += b.distance(p) <= 1e-9 * scale;
      on_sphere += b.distance(p) <= 1e-9 * scale;
      EXPECT_GE((p - b.c).norm(), b.r - 1e-9 * scale) << "vertex " << v << " inside a carved sphere";
    }
    EXPECT_GE(on, 1) << "boundary vertex " << v << " on no surface: " << p.transpose();
    curve += on >= 2;
  }
  EXPECT_GT(on_sphere, 300u);
  EXPECT_GT(curve, 80u);  // the creases: strings of edges on the curves
  ASSERT_EQ(m.face_sets.size(), 3u);  // "cut1".."cut3": boundary faces on each sphere
  const std::vector<QuadFace> all = build_quads(m);
  std::set<std::pair<Index, int>> boundary_faces;
  for (const QuadFace& q : all)
    if (q.is_boundary()) boundary_faces.insert({q.hex[0], q.local[0]});
  for (std::size_t j = 0; j < 3; ++j) {
    EXPECT_EQ(m.face_sets[j].name, "cut" + std::to_string(j + 1));
    EXPECT_EQ(m.face_sets[j].faces.size(), r.surface_quads[j].size());
    for (const auto& [h, f] : m.face_sets[j].faces) {
      EXPECT_TRUE(boundary_faces.count({h, f})) << "hex " << h << " face " << int(f);
      for (Index v : face_vertices(m.hexes[h], f)) EXPECT_LE(balls[j].distance(m.points[v]), 1e-9 * scale);
    }
  }
  for (std::size_t j = 0; j < 3; ++j) {
    EXPECT_GT(r.surface_quads[j].size(), 50u);
    EXPECT_LE(r.max_distance[j], 1e-9);
    for (const Quad& q : r.surface_quads[j])
      for (Index v : q) EXPECT_LE(balls[j].distance(m.points[v]), 1e-9 * scale);
  }
}

// Both sides kept: two blocks meeting on the plane in the same quads, the new sheets' hexes
// each with exactly one face on it, every interface vertex on the plane, and the crease where
// the plane meets the cube's faces sharp.
TEST(Cut, PlaneKeepsBothSidesConforming) {
  const Vec3 p0(1, 1, 1), n = Vec3(1, 0.3, 0.2).normalized();
  const CutResult r = cut(box_mesh(12, 12, 12, Vec3::Zero(), Vec3(2, 2, 2)), {Shape::plane(p0, Vec3(1, 0.3, 0.2))});
  const HexMesh& m = r.mesh;
  EXPECT_TRUE(validate(m).valid());
  EXPECT_EQ(below(m, 0.2), 0u);
  EXPECT_EQ(not_certified(m), 0u);
  ASSERT_TRUE(m.has_blocks());
  std::set<Index> blocks(m.blocks.begin(), m.blocks.end());
  EXPECT_EQ(blocks, (std::set<Index>{0, 1}));
  // The interface: interior quads between the blocks; their vertices on the plane.
  std::map<Index, int> faces_on_cut;
  std::size_t interface = 0;
  for (const QuadFace& q : build_quads(m)) {
    ASSERT_EQ(q.extra_hexes, 0);
    if (q.is_boundary() || m.blocks[q.hex[0]] == m.blocks[q.hex[1]]) continue;
    ++interface;
    ++faces_on_cut[q.hex[0]], ++faces_on_cut[q.hex[1]];
    for (Index v : q.vertices) EXPECT_LE(std::abs(n.dot(m.points[v] - p0)), 1e-9) << "vertex " << v;
    // Inside (behind the plane) is the new block 1.
    const Vec3 c0 = (m.points[m.hexes[q.hex[0]][0]] + m.points[m.hexes[q.hex[0]][6]]) / 2;
    EXPECT_EQ(m.blocks[q.hex[0]], n.dot(c0 - p0) < 0 ? 1 : 0);
  }
  EXPECT_EQ(interface, r.surface_quads[0].size());
  EXPECT_GT(interface, 150u);
  // The two sides as face sets: the faces of the inside (block 1) and outside hexes on the plane.
  ASSERT_EQ(m.face_sets.size(), 2u);
  EXPECT_EQ(m.face_sets[0].name, "cut1_inside");
  EXPECT_EQ(m.face_sets[1].name, "cut1_outside");
  for (const FaceSet& fs : m.face_sets) {
    EXPECT_EQ(fs.faces.size(), interface);
    for (const auto& [h, f] : fs.faces) {
      EXPECT_EQ(m.blocks[h], fs.name == "cut1_inside" ? 1 : 0);
      for (Index v : face_vertices(m.hexes[h], f)) EXPECT_LE(std::abs(n.dot(m.points[v] - p0)), 1e-9);
    }
  }
  for (const auto& [h, k] : faces_on_cut) EXPECT_EQ(k, 1) << "hex " << h << " has " << k << " faces on the cut";
  // Sharp creases: keep one side, and across every boundary edge on the plane the two quads'
  // normals differ by the angle between the plane and the cube's face.
  CutOptions in;
  in.keep = CutKeep::inside;
  const HexMesh half = cut(box_mesh(12, 12, 12, Vec3::Zero(), Vec3(2, 2, 2)), {Shape::plane(p0, Vec3(1, 0.3, 0.2))}, in).mesh;
  std::size_t creases = 0;
  for (const auto& [e, ns] : boundary_edge_normals(half)) {
    ASSERT_EQ(ns.size(), 2u);
    const bool a_on = std::abs(ns[0].dot(n) - 1) < 1e-6, b_on = std::abs(ns[1].dot(n) - 1) < 1e-6;
    if (a_on == b_on) continue;
    ++creases;
    const Vec3 face = a_on ? ns[1] : ns[0];  // an axis direction
    EXPECT_NEAR(face.cwiseAbs().maxCoeff(), 1.0, 1e-9) << "edge " << e.first << "-" << e.second;
    EXPECT_NEAR(std::acos(std::clamp(ns[0].dot(ns[1]), -1.0, 1.0)), std::acos(std::clamp(n.dot(face), -1.0, 1.0)), 1e-6);
  }
  EXPECT_GT(creases, 40u);
}

// A plane through the middle of a layer of hexes whose vertices are a little off the grid
// (as smoothing leaves them): the layer's centroids lie within the noise of the plane, on
// both sides of it. By their signs the interface zigzags between the layer's two faces; with
// a tie band (CutOptions::tie_band) the cut takes one face of the layer (one quad per column)
// and moves it onto the plane.
TEST(Cut, PlaneThroughTheMiddleOfALayer) {
  HexMesh box = box_mesh(8, 8, 8);
  jitter(box, 0.02 / 8, 3);  // well below the hex's size, enough to mix the centroids' signs
  const double y = 4.5 / 8;
  std::size_t above = 0, below_plane = 0;
  for (Index h = 0; h < box.num_hexes(); ++h) {
    const double c = box.centroid(h).y();
    if (std::abs(c - y) < 0.5 / 8) (c > y ? above : below_plane)++;
  }
  ASSERT_GT(above, 5u);  // the premise: the layer's signs are mixed
  ASSERT_GT(below_plane, 5u);
  const Shape plane = Shape::plane(Vec3(0, y, 0), Vec3(0, 1, 0));
  EXPECT_GT(cut(box, {plane}).surface_quads[0].size(), 64u);
  CutOptions o;
  o.tie_band = 0.05;
  const CutResult r = cut(box, {plane}, o);
  EXPECT_EQ(r.surface_quads[0].size(), 64u);
  EXPECT_EQ(below(r.mesh, 0.2), 0u);
  EXPECT_EQ(not_certified(r.mesh), 0u);
  EXPECT_GT(min_sj(r.mesh), 0.5);
}

// A plate one hex thick standing on a face of the box (cthead's head rest on the scan's bottom
// slice): its front and back are one surface, so the edge across its bottom has both ends on
// that surface and on the box face, yet it is not on their curve. A cut across the plate moves
// nothing there; treated as a curve edge, its ends went to one side one after another along the
// whole bottom (cthead h 4, sagittal plane: 14 hexes flattened to SJ 0).
TEST(Cut, PlaneAcrossAPlateOnABoxFace) {
  const Aabb domain{Vec3(0, 0, 0), Vec3(8, 0.5, 4)};
  const HexMesh plate = box_mesh(16, 1, 8, domain.lo, domain.hi);
  CutOptions o;
  o.feature_degrees = 180;
  o.boundary = {contour::LevelSet(std::make_shared<const Shape>(parse_shape("box(-1,0,-1, 9,0.5,5)")), 10.0),
                contour::LevelSet(domain, 4)};  // the plate's skin and the box face z = 0
  o.domain = domain;
  for (const double x : {4.1, 3.8}) {
    SCOPED_TRACE(x);
    const CutResult r = cut(plate, {Shape::plane(Vec3(x, 0, 0), Vec3(1, 0, 0))}, o);
    EXPECT_EQ(r.steps[0].moved_across, 0u);
    EXPECT_EQ(r.surface_quads[0].size(), 8u);  // the plate's section: one column of quads
    EXPECT_EQ(r.steps[0].corner_vertices, 2u);  // the plane, the plate's two faces and z = 0
    EXPECT_LE(r.max_distance[0], 1e-9);
    EXPECT_TRUE(validate(r.mesh).valid());
    EXPECT_EQ(below(r.mesh, 0.2), 0u);
    EXPECT_EQ(not_certified(r.mesh), 0u);
  }
}

// Other sizes and shapes, and a bumpy (jittered) cube, stay valid with nothing below 0.2.
TEST(Cut, OtherCellSizesAndShapes) {
  struct Case {
    int n;
    std::string shape;
    CutKeep keep;
    double jitter;
  };
  for (const Case& c : std::vector<Case>{{9, "sphere(2,2,2,1.2)", CutKeep::both, 0},
                                         {16, "cylinder(1,1,-1, 1,1,3, 0.5)", CutKeep::outside, 0},
                                         {12, "torus(1,1,1, 0.6,0.25)", CutKeep::both, 0},
                                         {10, "sphere(1,1,1,0.7)", CutKeep::inside, 0},
                                         {12, "plane(1,1,1, 1,0.3,0.2)", CutKeep::both, 0.2}}) {
    HexMesh box = box_mesh(c.n, c.n, c.n, Vec3::Zero(), Vec3(2, 2, 2));
    if (c.jitter > 0) jitter(box, c.jitter * 2.0 / c.n, 7);
    CutOptions opt;
    opt.keep = c.keep;
    const CutResult r = cut(box, {parse_shape(c.shape)}, opt);
    SCOPED_TRACE(c.shape + " n " + std::to_string(c.n));
    EXPECT_TRUE(validate(r.mesh).valid());
    EXPECT_EQ(below(r.mesh, 0.2), 0u);
    EXPECT_EQ(not_certified(r.mesh), 0u);
    EXPECT_LE(r.max_distance[0], 1e-9);
  }
}

TEST(Cut, ClearErrors) {
  const HexMesh box = box_mesh(6, 6, 6, Vec3::Zero(), Vec3(2, 2, 2));
  const auto message = [&](const std::vector<Shape>& s, CutKeep keep) {
    CutOptions opt;
    opt.keep = keep;
    try {
      cut(box, s, opt);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message({Shape::sphere(Vec3(5, 5, 5), 1)}, CutKeep::both).find("misses the mesh: every hex is outside"),
            std::string::npos);
  EXPECT_NE(message({Shape::sphere(Vec3(1, 1, 1), 5)}, CutKeep::both).find("every hex is inside"), std::string::npos);
  // A second cut in the part the first one dropped.
  EXPECT_NE(message({Shape::sphere(Vec3(0, 0, 0), 1), Shape::sphere(Vec3(0, 0, 0), 0.5)}, CutKeep::outside)
                .find("misses the mesh"),
            std::string::npos);
  EXPECT_NE(message({}, CutKeep::both).find("no cut surface"), std::string::npos);
}

// The same mesh, bit for bit, on one thread and on two.
TEST(Cut, SameBitsForAnyThreadCount) {
  const HexMesh box = box_mesh(10, 10, 10, Vec3::Zero(), Vec3(2, 2, 2));
  const std::vector<Shape> s{Shape::sphere(Vec3(2, 2, 2), 1.2), Shape::sphere(Vec3(2, 0.8, 1.0), 0.75)};
  HexMesh one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = cut(box, s).mesh;
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = cut(box, s).mesh;
  }
  ASSERT_EQ(one.points.size(), two.points.size());
  EXPECT_TRUE(std::equal(one.points.begin(), one.points.end(), two.points.begin(),
                         [](const Vec3& a, const Vec3& b) { return a.x() == b.x() && a.y() == b.y() && a.z() == b.z(); }));
  EXPECT_EQ(one.hexes, two.hexes);
  EXPECT_EQ(one.blocks, two.blocks);
}

// A shape's level set: positive inside, projection onto the surface, its gradient.
TEST(Cut, ShapeLevelSet) {
  const contour::LevelSet s(std::make_shared<const Shape>(Shape::sphere(Vec3(1, 2, 3), 0.5)), 1.0);
  EXPECT_NEAR(s.level(Vec3(1, 2, 3)), 0.5, 1e-15);
  Vec3 g;
  EXPECT_NEAR(s.level(Vec3(2, 2, 3), g), -0.5, 1e-15);
  EXPECT_NEAR((g - Vec3(-1, 0, 0)).norm(), 0, 1e-6);
  Vec3 p(1.3, 2.4, 3.1);
  ASSERT_TRUE(s.project(p, 1.0));
  EXPECT_NEAR((p - Vec3(1, 2, 3)).norm(), 0.5, 1e-10);
  Vec3 far(9, 9, 9);
  EXPECT_FALSE(s.project(far, 0.1));  // beyond the reach
  EXPECT_NE(s.describe().find("sphere(1, 2, 3, 0.5)"), std::string::npos);
  const Vec3 r = s.root(Vec3(1, 2, 3), Vec3(2, 2, 3));  // from inside to outside
  EXPECT_NEAR(r.x(), 1.5, 1e-9);
}

// A cut along a volume's isosurface: a torus's distance sampled every 0.04 (trilinear), its
// isovalue 0 cutting the 12^3 cube into two conforming blocks. The cut vertices are on the
// sampled field's isosurface (to 1e-7 of its range) and so within the interpolation error of the
// exact torus.
TEST(Cut, AlongAVolumesIsosurface) {
  const Vec3 c(1, 1, 1);
  const double major = 0.55, minor = 0.25;
  const Volume vol = sample(Shape::torus(c, Vec3(0, 0, 1), major, minor),
                            grid_from_cell_size({Vec3::Constant(-0.2), Vec3::Constant(2.2)}, 0.04));
  const auto field = std::make_shared<const IsoField>(vol, 0.0, Inside::below);
  const CutResult r = cut(box_mesh(12, 12, 12, Vec3::Zero(), Vec3(2, 2, 2)), {contour::LevelSet(field)});
  const HexMesh& m = r.mesh;
  EXPECT_TRUE(validate(m).valid());
  EXPECT_EQ(below(m, 0.2), 0u);
  EXPECT_GE(min_sj(m), 0.3);
  EXPECT_EQ(not_certified(m), 0u);
  ASSERT_EQ(r.surface_quads.size(), 1u);
  EXPECT_GT(r.surface_quads[0].size(), 150u);
  EXPECT_LE(r.max_distance[0], 1e-7);
  // Exact distance to the torus (the oracle), and the two blocks share exactly the cut's quads.
  const auto torus_distance = [&](const Vec3& p) {
    const Vec3 d = p - c;
    return std::abs(std::hypot(std::hypot(d.x(), d.y()) - major, d.z()) - minor);
  };
  double far = 0;
  for (const Quad& q : r.surface_quads[0])
    for (Index v : q) far = std::max(far, torus_distance(m.points[v]));
  EXPECT_LE(far, 2e-3);  // trilinear interpolation of the distance at spacing 0.04
  std::set<std::array<Index, 4>> faces[2];
  for (Index h = 0; h < m.num_hexes(); ++h)
    for (int f = 0; f < 6; ++f) {
      const Quad q = face_vertices(m.hexes[h], f);
      if (std::all_of(q.begin(), q.end(), [&](Index v) { return torus_distance(m.points[v]) <= 2e-3; })) {
        std::array<Index, 4> k = q;
        std::sort(k.begin(), k.end());
        faces[m.blocks[h] == 0 ? 0 : 1].insert(k);
      }
    }
  EXPECT_EQ(faces[0], faces[1]);
  EXPECT_EQ(faces[0].size(), r.surface_quads[0].size());
  // The face sets name both sides of the interface.
  ASSERT_EQ(m.face_sets.size(), 2u);
  EXPECT_EQ(m.face_sets[0].name, "cut1_inside");
  EXPECT_EQ(m.face_sets[1].name, "cut1_outside");
}

TEST(Cut, CommandLine) {
  const auto dir = scratch_dir();
  ASSERT_EQ(run_cli("generate box -n 8 --size 2 -o " + quote(dir / "cube8.vtu")), 0);
  std::string out;
  const auto j = cut_report(dir, "cube8.vtu", "carved.vtu", "--surface 'sphere(2,2,2,1.1)' --keep outside", out);
  EXPECT_EQ(j["quality"]["below_0.2"].get<int>(), 0);
  EXPECT_EQ(j["validity"]["not_valid_inside"].get<int>(), 0);
  EXPECT_EQ(j["cuts"][0]["sheet_hexes"].get<int>(), j["cuts"][0]["surface_quads"].get<int>());  // one sheet (one side kept)
  EXPECT_LE(j["cuts"][0]["max_relative_distance"].get<double>(), 1e-9);
  EXPECT_EQ(run_cli("quality " + quote(dir / "carved.vtu"), &out), 0) << out;
  // The cut's faces as an Abaqus surface of their own, and an Exodus side set.
  ASSERT_EQ(run_cli("cut " + quote(dir / "cube8.vtu") + " -o " + quote(dir / "carved.inp") +
                        " --surface 'sphere(2,2,2,1.1)' --keep outside",
                    &out),
            0)
      << out;
  const std::string inp = io::read_file(dir / "carved.inp");
  EXPECT_NE(inp.find("*SURFACE, NAME=CUT1, TYPE=ELEMENT"), std::string::npos);
  EXPECT_NE(inp.find("*SURFACE, NAME=BOUNDARY, TYPE=ELEMENT"), std::string::npos);
  EXPECT_EQ(run_cli("check " + quote(dir / "carved.inp"), &out), 0) << out;
  // A bad expression: exit 2, the option and the column named, nothing written.
  EXPECT_EQ(run_cli("cut " + quote(dir / "cube8.vtu") + " -o " + quote(dir / "bad.vtu") + " --surface 'sphere(1,2'",
                    &out),
            2);
  EXPECT_NE(out.find("--surface 1"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.vtu"));
  EXPECT_EQ(run_cli("cut " + quote(dir / "cube8.vtu") + " -o " + quote(dir / "bad.vtu") + " --surface 'sphere(9,9,9,1)'",
                    &out),
            2);
  EXPECT_NE(out.find("misses the mesh"), std::string::npos) << out;
}

// A plane meeting the face x = 0 of the 12³ cube at 20°: by the signs alone a hex is left
// inverted at the wedge's tip; the second cut, with a tie band, leaves none. The hexes at the
// corner of the plane and the faces x = 0 and y = 2 cannot do better than 0.109: a hex corner
// there has its three edges on the three creases, whose unit directions (0, 0, 1),
// (0, -0.2, 0.3) / |.|, (0.2, 0, -1) / |.| have that determinant.
TEST(Cut, CommandLineCutsAgainWithATieBand) {
  const auto dir = scratch_dir();
  ASSERT_EQ(run_cli("generate box -n 12 --size 2 -o " + quote(dir / "cube12.vtu")), 0);
  std::string out;
  const auto j = cut_report(dir, "cube12.vtu", "wedge.vtu", "--surface 'plane(0.5,0.5,0.5, 1,0.3,0.2)'", out);
  ASSERT_TRUE(j.contains("attempts")) << out;
  EXPECT_EQ(j["attempts"]["kept"], "tie_band");
  EXPECT_LT(j["attempts"]["first"]["min_sj"].get<double>(), 0.01);
  EXPECT_EQ(j["quality"]["inverted"].get<int>(), 0);
  EXPECT_EQ(j["validity"]["not_valid_inside"].get<int>(), 0);
  const Vec3 a(0, 0, 1), b = Vec3(0, -0.2, 0.3).normalized(), c = Vec3(0.2, 0, -1).normalized();
  const double bound = std::abs(a.dot(b.cross(c)));
  EXPECT_NEAR(j["quality"]["min"].get<double>(), bound, 2e-3);
  // Asked for by hand, the tie band runs once.
  const auto k =
      cut_report(dir, "cube12.vtu", "wedge2.vtu", "--surface 'plane(0.5,0.5,0.5, 1,0.3,0.2)' --tie-band 0.05", out);
  EXPECT_FALSE(k.contains("attempts"));
  EXPECT_EQ(k["quality"]["min"], j["quality"]["min"]);
}

namespace {

// The boundary edges whose two quads' normals differ by more than `degrees`: (edge, angle).
std::vector<double> crease_angles(const HexMesh& m, double degrees) {
  std::vector<double> out;
  for (const auto& [e, ns] : boundary_edge_normals(m)) {
    if (ns.size() != 2) continue;
    const double a = std::acos(std::clamp(ns[0].dot(ns[1]), -1.0, 1.0)) * 180 / std::numbers::pi;
    if (a > degrees) out.push_back(a);
  }
  return out;
}

}  // namespace

// CSG by cuts (`--features sheets`): a plate with a hole. Every boundary vertex on the exact
// surface (a face of the plate, or the hole's wall within the plate's thickness), the creases
// (the hole's two rims) strings of edges on the exact circles and sharp: the quads across them
// meet at the solid's 90 degrees, not rounded.
TEST(Cut, CsgPlateWithAHoleHasExactCreases) {
  const Shape plate = parse_shape("difference(box(0,0,0, 2,2,1), cylinder(1,1,-1, 1,1,2, 0.5))");
  CsgMeshOptions opt;
  opt.cell_size = 0.1;
  const CsgMeshResult r = mesh_by_cuts(plate, opt);
  const HexMesh& m = r.mesh;
  EXPECT_TRUE(validate(m).valid());
  EXPECT_EQ(below(m, 0.2), 0u);
  EXPECT_EQ(not_certified(m), 0u);
  const double size = 3, tol = 1e-6 * size;
  std::set<Index> boundary;
  for (const Quad& q : boundary_quads(m))
    for (Index v : q) boundary.insert(v);
  std::size_t rim = 0;
  for (Index v : boundary) {
    const Vec3& p = m.points[v];
    const double wall = std::abs(std::hypot(p.x() - 1, p.y() - 1) - 0.5);
    const bool on_face = std::abs(p.x()) <= tol || std::abs(p.x() - 2) <= tol || std::abs(p.y()) <= tol ||
                         std::abs(p.y() - 2) <= tol || std::abs(p.z()) <= tol || std::abs(p.z() - 1) <= tol;
    EXPECT_TRUE(on_face || (wall <= tol && p.z() >= -tol && p.z() <= 1 + tol)) << "vertex " << v << " " << p.transpose();
    EXPECT_GE(std::hypot(p.x() - 1, p.y() - 1), 0.5 - tol) << "vertex " << v << " inside the hole";
    rim += wall <= tol && (std::abs(p.z()) <= tol || std::abs(p.z() - 1) <= tol);
  }
  EXPECT_GT(rim, 50u);  // the two rims, on the exact circles
  // Sharp: the hole's rims (and the plate's own edges) at 90 degrees within 2 degrees.
  std::size_t right = 0;
  for (double a : crease_angles(m, 30)) {
    EXPECT_NEAR(a, 90, 2);
    ++right;
  }
  EXPECT_GT(right, 100u);
}

TEST(Cut, CsgSphereCutByABoxHasItsCircles) {
  const Shape s = parse_shape("intersection(sphere(0,0,0,1), box(-0.75,-0.75,-0.75, 0.75,0.75,0.75))");
  CsgMeshOptions opt;
  opt.cell_size = 0.1;
  const CsgMeshResult r = mesh_by_cuts(s, opt);
  const HexMesh& m = r.mesh;
  EXPECT_TRUE(validate(m).valid());
  EXPECT_EQ(below(m, 0.2), 0u);
  EXPECT_EQ(not_certified(m), 0u);
  const double tol = 1e-6 * 2;
  std::size_t circle = 0;
  for (const Quad& q : boundary_quads(m))
    for (Index v : q) {
      const Vec3& p = m.points[v];
      const bool on_sphere = std::abs(p.norm() - 1) <= tol, on_face = std::abs(p.cwiseAbs().maxCoeff() - 0.75) <= tol;
      EXPECT_TRUE(on_sphere || on_face) << p.transpose();
      EXPECT_LE(p.cwiseAbs().maxCoeff(), 0.75 + tol);
      EXPECT_LE(p.norm(), 1 + tol);
      circle += on_sphere && on_face;
    }
  EXPECT_GT(circle, 100u);  // counted once per quad corner: the six circles
  // The sphere meets each face at 180 - acos(0.75) = 138.6 degrees inside: quads across the
  // circles turn by about 41.4 degrees (the sphere's quads are chords: within 8).
  std::size_t creases = 0;
  for (double a : crease_angles(m, 25)) {
    EXPECT_NEAR(a, std::acos(0.75) * 180 / std::numbers::pi, 8);
    ++creases;
  }
  EXPECT_GT(creases, 40u);
}

// `isohex mesh --cut`: a sampled ball cut by a plane after pillowing, one side kept; the crease
// vertices on the isosurface (the report's distances) and on the plane, nothing below 0.2.
TEST(Cut, MeshPipelineCutsAlongAPlane) {
  const auto dir = scratch_dir();
  for (const std::string keep : {"outside", "both"}) {
    std::string out;
    const auto json = dir / ("mesh_cut_" + keep + ".json");
    ASSERT_EQ(run_cli("mesh --shape 'sphere(0,0,0,1)' --resolution 20 --cut 'plane(0.1,0.2,0.1, 1,0.5,0.3)' --keep " + keep +
                          " -o " + quote(dir / ("mesh_cut_" + keep + ".vtu")) + " --json " + quote(json),
                      &out),
              0)
        << out;
    const auto j = nlohmann::json::parse(io::read_file(json));
    SCOPED_TRACE(keep);
    const auto& c = j["cutting"]["cuts"][0];
    EXPECT_GT(c["curve_vertices"].get<int>(), 40);
    EXPECT_LE(c["final_max_relative_distance"].get<double>(), 1e-9);
    EXPECT_LE(j["max_relative_distance"].get<double>(), 1e-6);  // every vertex on the isosurface, the crease's too
    EXPECT_EQ(j["scaled_jacobian"]["inverted"].get<int>() + j["scaled_jacobian"]["questionable"].get<int>(), 0);
    EXPECT_EQ(j["validity"]["not_valid_inside"].get<int>(), 0);
    EXPECT_TRUE(j["valid"].get<bool>());
  }
  std::string out;
  EXPECT_EQ(run_cli("mesh --shape 'sphere(0,0,0,1)' --resolution 8 --keep inside -o " + quote(dir / "k.vtu"), &out), 2);
  EXPECT_NE(out.find("--keep is only used with --cut"), std::string::npos) << out;
  EXPECT_EQ(run_cli("mesh --shape 'sphere(0,0,0,1)' --resolution 8 --cut 'plane(0,0' -o " + quote(dir / "k.vtu"), &out), 2);
  EXPECT_NE(out.find("--cut 1"), std::string::npos) << out;
}

TEST(Cut, MeshFeaturesSheetsCommandLine) {
  const auto dir = scratch_dir();
  std::string out;
  const auto json = dir / "plate.json";
  ASSERT_EQ(run_cli("mesh --shape 'difference(box(0,0,0, 2,2,1), cylinder(1,1,-1, 1,1,2, 0.5))' --features sheets "
                    "--cell-size 0.125 -o " + quote(dir / "plate.vtu") + " --json " + quote(json),
                    &out),
            0)
      << out;
  const auto j = nlohmann::json::parse(io::read_file(json));
  EXPECT_EQ(j["features"], "sheets");
  EXPECT_EQ(j["skipped_faces"].get<int>(), 6);
  EXPECT_EQ(j["pieces"][0]["missed"].get<bool>(), false);
  EXPECT_LE(j["pieces"][0]["max_relative_distance"].get<double>(), 1e-9);
  EXPECT_GT(j["pieces"][0]["curve_vertices"].get<int>(), 40);
  EXPECT_EQ(j["scaled_jacobian"]["inverted"].get<int>() + j["scaled_jacobian"]["questionable"].get<int>(), 0);
  EXPECT_EQ(j["validity"]["not_valid_inside"].get<int>(), 0);
  EXPECT_EQ(run_cli("quality " + quote(dir / "plate.vtu"), &out), 0) << out;
  const auto vol = dir / "ball.nrrd";
  ASSERT_EQ(run_cli("volume shape 'sphere(0,0,0,1)' -o " + quote(vol) + " --cell-size 0.25", &out), 0) << out;
  EXPECT_EQ(run_cli("mesh " + quote(vol) + " --iso 0 --features sheets -o " + quote(dir / "x.vtu"), &out), 2);
  EXPECT_NE(out.find("--features sheets meshes a --shape"), std::string::npos) << out;
}

}  // namespace isohex::test
