#pragma once
// Helpers for the surface-smoothing tests: sampled fields, a torus hex mesh, boundary noise.
// Header-only: tests/CMakeLists.txt compiles the *_test.cpp files and test_support.cpp only.

#include "isohex/contour/iso_field.hpp"
#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/volume/implicit.hpp"

#include "isohex/mesh/topology.hpp"
#include "isohex/quality/hex_quality.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace isohex::test {

/// A shape sampled on a `n`³ grid over its sampling bounds (signed distance: inside below 0).
inline Volume sampled(const Shape& shape, Index n) { return sample(shape, grid_from_dims(sampling_bounds(shape), {n, n, n})); }

/// A hex torus about the z axis: an m × m grid on [-1, 1]² mapped onto the disk of radius
/// `minor` (the ball_mesh mapping in 2-D), swept over `segments` steps around the circle of
/// radius `major`. Positively oriented.
inline HexMesh torus_mesh(double major, double minor, int m, int segments) {
  HexMesh mesh;
  auto id = [&](int i, int j, int k) { return static_cast<Index>(i + (m + 1) * (j + (m + 1) * (k % segments))); };
  for (int k = 0; k < segments; ++k) {
    const double phi = 2 * std::numbers::pi * k / segments;
    for (int j = 0; j <= m; ++j)
      for (int i = 0; i <= m; ++i) {
        double u = -1 + 2.0 * i / m, v = -1 + 2.0 * j / m;
        const double r2 = std::hypot(u, v);
        if (r2 > 0) {
          const double s = minor * std::max(std::abs(u), std::abs(v)) / r2;
          u *= s;
          v *= s;
        }
        mesh.points.emplace_back((major + u) * std::cos(phi), (major + u) * std::sin(phi), v);
      }
  }
  for (int k = 0; k < segments; ++k)
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i)
        mesh.hexes.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k), id(i, j, k + 1),
                              id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)});
  if (volume(mesh.corners(0)) < 0)
    for (Hex& h : mesh.hexes) {
      std::swap(h[1], h[3]);
      std::swap(h[5], h[7]);
    }
  return mesh;
}

/// Adds a uniform random offset in [-amplitude, amplitude]³ to every boundary vertex, then
/// projects it onto the isosurface of `field` (deterministic for a seed).
inline void jitter_boundary(HexMesh& mesh, const IsoField& field, double amplitude, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  const auto boundary = boundary_vertex_mask(mesh);
  for (std::size_t v = 0; v < mesh.points.size(); ++v) {
    if (!boundary[v]) continue;
    Vec3& p = mesh.points[v];
    p += Vec3(u(rng), u(rng), u(rng));
    field.project(p, 10 * amplitude, 1e-9 * field.value_range());
  }
}

/// Sum of the hexes' signed volumes.
inline double mesh_volume(const HexMesh& mesh) {
  double sum = 0;
  for (Index h = 0; h < mesh.num_hexes(); ++h) sum += volume(mesh.corners(h));
  return sum;
}

/// Largest |L| over the boundary vertices.
inline double max_boundary_level(const HexMesh& mesh, const IsoField& field) {
  const auto boundary = boundary_vertex_mask(mesh);
  double worst = 0;
  for (std::size_t v = 0; v < mesh.points.size(); ++v)
    if (boundary[v]) worst = std::max(worst, std::abs(field.level(mesh.points[v])));
  return worst;
}

}  // namespace isohex::test
