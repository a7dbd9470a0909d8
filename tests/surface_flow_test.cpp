// The pieces of surface smoothing: boundary graph and creases, the interior band, the
// colouring, the surface-diffusion operator and the move guard.
#include "isohex/mesh/generate.hpp"
#include "isohex/surface/surface_graph.hpp"
#include "isohex/surface/vertex_moves.hpp"
#include "surface_support.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

using namespace isohex;
using namespace isohex::surface_detail;

namespace {

constexpr double kCos60 = 0.5;

std::size_t count(const std::vector<std::uint8_t>& mask) {
  std::size_t n = 0;
  for (auto b : mask) n += b != 0;
  return n;
}

}  // namespace

TEST(SurfaceGraph, BoundaryAndCreasesOfABox) {
  const HexMesh m = test::grid_mesh(2, 3, 4);
  const SurfaceGraph g = build_surface_graph(m, kCos60);
  EXPECT_EQ(g.quads.size(), 2u * (2 * 3 + 3 * 4 + 2 * 4));
  EXPECT_EQ(count(g.on_boundary), 3u * 4 * 5 - 1u * 2 * 3);
  // Crease vertices: the 8 corners and the inner vertices of the 12 edges.
  EXPECT_EQ(count(g.on_crease), 8u + 4 * (1 + 2 + 3));
  // A corner has three boundary neighbours, an edge vertex four, a face vertex four.
  EXPECT_EQ(g.boundary_neighbours.count(0), 3u);
  const SurfaceGraph none = build_surface_graph(m, -1.0);  // 180°: nothing is a crease
  EXPECT_EQ(count(none.on_crease), 0u);
}

TEST(SurfaceGraph, NonManifoldEdgeIsACrease) {
  // Two cubes sharing only the edge (1,0,z): that boundary edge has four quads.
  HexMesh m = test::grid_mesh(2, 2, 1);
  m.hexes = {m.hexes[0], m.hexes[3]};
  const SurfaceGraph g = build_surface_graph(m, -1.0);
  std::size_t creased = 0;
  for (Index v = 0; v < m.num_vertices(); ++v)
    if (g.on_crease[v]) {
      ++creased;
      EXPECT_EQ(m.points[v].x(), 1.0);
      EXPECT_EQ(m.points[v].y(), 1.0);
    }
  EXPECT_EQ(creased, 2u);
}

TEST(SurfaceGraph, InteriorBandLayers) {
  const HexMesh m = test::grid_mesh(4, 4, 4);  // interior vertices: 3³, the centre two layers deep
  const SurfaceGraph g = build_surface_graph(m, kCos60);
  EXPECT_EQ(interior_band(m, g, 0, {}).size(), 0u);
  EXPECT_EQ(interior_band(m, g, 1, {}).size(), 26u);
  const auto two = interior_band(m, g, 2, {});
  EXPECT_EQ(two.size(), 27u);
  EXPECT_TRUE(std::is_sorted(two.begin(), two.end()));
  std::vector<std::uint8_t> pinned(m.points.size(), 0);
  pinned[two[4]] = 1;
  EXPECT_EQ(interior_band(m, g, 2, pinned).size(), 26u);
}

TEST(SurfaceGraph, ColourClassesShareNoHex) {
  const HexMesh m = ball_mesh(5);
  const SurfaceGraph g = build_surface_graph(m, kCos60);
  std::vector<Index> all(m.points.size());
  for (Index v = 0; v < m.num_vertices(); ++v) all[v] = v;
  const auto classes = colour_classes(all, m, g.vertex_hexes);
  EXPECT_EQ(classes.size(), 8u);  // a structured grid needs exactly 8
  std::size_t total = 0;
  for (const auto& cls : classes) {
    total += cls.size();
    EXPECT_TRUE(std::is_sorted(cls.begin(), cls.end()));
    const std::set<Index> members(cls.begin(), cls.end());
    for (const Hex& h : m.hexes) {
      int in = 0;
      for (Index v : h) in += members.count(v) > 0;
      EXPECT_LE(in, 1);
    }
  }
  EXPECT_EQ(total, all.size());
}

// The max–min pass moves the members of a class in parallel. With the hex guard on (no pillow
// follows), a move reads every corner of the vertex's hexes, so no two members may share a hex.
// A slab one cell thick has hexes whose top and bottom vertices are both on the boundary but
// not near each other through the quads: the quad reads alone put such pairs in one class.
TEST(SurfaceGraph, ReadDisjointClassesHonourTheHexGuard) {
  const HexMesh m = box_mesh(4, 4, 1);
  const SurfaceGraph g = build_surface_graph(m, kCos60);
  std::vector<Index> all(m.points.size());
  for (Index v = 0; v < m.num_vertices(); ++v) all[v] = v;  // every vertex of a slab is on the boundary
  const auto shared_hexes = [&](const std::vector<std::vector<Index>>& classes) {
    std::size_t shared = 0;
    for (const auto& cls : classes) {
      const std::set<Index> members(cls.begin(), cls.end());
      for (const Hex& h : m.hexes) {
        int in = 0;
        for (Index v : h) in += members.count(v) > 0;
        shared += in > 1;
      }
    }
    return shared;
  };
  EXPECT_GT(shared_hexes(read_disjoint_classes(all, g)), 0u);  // quads only: the race that was
  const auto guarded = read_disjoint_classes(all, g, &m);
  EXPECT_EQ(shared_hexes(guarded), 0u);
  std::size_t total = 0;
  for (const auto& cls : guarded) total += cls.size();
  EXPECT_EQ(total, all.size());
}

TEST(SurfaceFlow, DiffusionFlattensABumpAndKeepsVolume) {
  // The top face z = 0 of an 8 x 8 x 2 block, its centre vertex raised: surface diffusion
  // must push the bump down and its ring up, with normal moves summing to zero (volume kept).
  const Volume vol = test::sampled(Shape::box(Vec3(-4, -4, -2), Vec3(4, 4, 0)), 61);
  const IsoField field(vol, 0, Inside::below);
  HexMesh m = box_mesh(8, 8, 2, Vec3(-4, -4, -2), Vec3(4, 4, 0));
  const SurfaceGraph g = build_surface_graph(m, kCos60);
  const MoveContext ctx{m, g, field, 0.2, 0.2, 0.0, 4, 1e-7 * field.value_range(), 1.0};
  Index bump = -1;
  for (Index v = 0; v < m.num_vertices(); ++v)
    if (m.points[v] == Vec3(0, 0, 0)) bump = v;
  ASSERT_GE(bump, 0);
  m.points[bump].z() = 0.2;

  std::vector<double> curvature(m.points.size(), 0.0);
  for (Index v = 0; v < m.num_vertices(); ++v)
    if (g.on_boundary[v]) curvature[v] = quad_umbrella(ctx, v).dot(outward_normal(ctx, v));
  EXPECT_LT(curvature[bump], 0);  // a bump: its centroid lies below it
  double sum = 0;
  for (Index v = 0; v < m.num_vertices(); ++v) {
    const Vec3& p = m.points[v];
    if (!g.on_boundary[v] || std::abs(p.x()) > 2.5 || std::abs(p.y()) > 2.5 || p.z() < -0.5) continue;
    const Vec3 step = boundary_step(ctx, v, curvature, 0.0, 0.2);
    EXPECT_NEAR(step.x(), 0, 1e-12);
    EXPECT_NEAR(step.y(), 0, 1e-12);
    if (v == bump) EXPECT_LT(step.z(), -0.01);
    if (std::abs(p.x()) + std::abs(p.y()) == 1) EXPECT_GT(step.z(), 0.001);  // the bump's edge ring rises
    sum += step.z();
  }
  EXPECT_NEAR(sum, 0, 1e-12);
}

TEST(SurfaceFlow, TangentialStepLiesInTheTangentPlane) {
  const Volume vol = test::sampled(Shape::sphere(Vec3::Zero(), 1.0), 40);
  const IsoField field(vol, 0, Inside::below);
  HexMesh m = ball_mesh(6);
  test::jitter_boundary(m, field, 0.05, 2);
  const SurfaceGraph g = build_surface_graph(m, kCos60);
  const MoveContext ctx{m, g, field, 0.2, 0.2, 0.0, 4, 1e-7 * field.value_range(), 1.0};
  const std::vector<double> curvature(m.points.size(), 0.0);
  double largest = 0;
  for (Index v = 0; v < m.num_vertices(); ++v) {
    if (!g.on_boundary[v]) continue;
    const Vec3 n = outward_normal(ctx, v);
    EXPECT_GT(n.dot(m.points[v].normalized()), 0.99);  // outward on a sphere
    const Vec3 step = boundary_step(ctx, v, curvature, 1.0, 0.0);
    EXPECT_NEAR(step.dot(n), 0, 1e-12);
    largest = std::max(largest, step.norm());
  }
  EXPECT_GT(largest, 0.01);  // the jitter left something to relax
}

TEST(SurfaceFlow, GuardRejectsInvertingMovesAndHalvesSteps) {
  const Volume vol = test::sampled(Shape::sphere(Vec3::Zero(), 1.0), 20);
  const IsoField field(vol, 0, Inside::below);
  HexMesh m = test::grid_mesh(1, 1, 1);
  const SurfaceGraph g = build_surface_graph(m, kCos60);
  const MoveContext ctx{m, g, field, 0.2, 0.2, 0.0, 3, 1e-7 * field.value_range(), 1.0};
  // Vertex 0 at the origin: past the opposite corner inverts, a small move is fine.
  EXPECT_FALSE(move_is_acceptable(ctx, 0, Vec3(1.5, 1.5, 1.5), false, Check::relax));
  EXPECT_TRUE(move_is_acceptable(ctx, 0, Vec3(0.1, 0.05, 0), false, Check::relax));
  // SJ 1 -> 0.18: above 0 (the projection check) but below the 0.2 floor.
  const Vec3 flat(0.3, 0.3, 0.3);
  EXPECT_FALSE(move_is_acceptable(ctx, 0, flat, false, Check::relax));
  EXPECT_TRUE(move_is_acceptable(ctx, 0, flat, false, Check::project));
  // A move that is too long is halved until acceptable: 1.6, 0.8 and 0.4 along the diagonal
  // invert the hex, 0.2 does not.
  EXPECT_EQ(move_interior_vertex(ctx, 0, Vec3(1.6, 1.6, 1.6)), MoveOutcome::halved);
  EXPECT_NEAR(m.points[0].x(), 0.2, 1e-12);
  // With no step-backs allowed, the same move is dropped.
  MoveContext strict = ctx;
  strict.max_halvings = 0;
  const Vec3 kept = m.points[0];
  EXPECT_EQ(move_interior_vertex(strict, 0, Vec3(1.6, 1.6, 1.6)), MoveOutcome::dropped);
  EXPECT_EQ(m.points[0], kept);
  EXPECT_EQ(move_interior_vertex(ctx, 0, Vec3::Zero()), MoveOutcome::none);
}

TEST(SurfaceFlow, FloorRule) {
  // Soft floor 0.2, hard floor 0.
  EXPECT_TRUE(keeps_floors(0.9, 0.25, 0.2, 0.0));
  EXPECT_FALSE(keeps_floors(0.9, 0.15, 0.2, 0.0));   // crosses the soft floor
  EXPECT_TRUE(keeps_floors(0.1, 0.05, 0.2, 0.0));    // free between the floors
  EXPECT_FALSE(keeps_floors(0.1, -0.01, 0.2, 0.0));  // would invert
  EXPECT_TRUE(keeps_floors(-0.5, -0.4, 0.2, 0.0));   // inverted, improving
  EXPECT_FALSE(keeps_floors(-0.5, -0.6, 0.2, 0.0));  // inverted, worsening
  EXPECT_TRUE(keeps_floors(0.2, 0.2, 0.2, 0.0));
}
