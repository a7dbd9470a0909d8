#pragma once
/// \file generate.hpp
/// \brief Simple meshes made from nothing: structured boxes and a mapped ball.
///
/// Used by tests, benchmarks and the README's default job. The ball is the classic
/// cube-to-sphere mapping whose elements along the cube's diagonals are flattened: a
/// realistic "before" mesh with poor elements next to the boundary.

#include "isohex/mesh/hex_mesh.hpp"

namespace isohex {

/// An nx × ny × nz grid of hexes filling the box [lo, hi]; vertices numbered x fastest.
HexMesh box_mesh(int nx, int ny, int nz, const Vec3& lo = Vec3::Zero(), const Vec3& hi = Vec3::Ones());

/// A ball of radius `radius` centred at the origin: an n³ grid on [-1, 1]³ mapped radially
/// (p ↦ p·|p|∞/|p|₂) onto the ball. n ≥ 1.
HexMesh ball_mesh(int n, double radius = 1.0);

/// Moves every vertex by a uniform random offset in [-amplitude, amplitude]³ (deterministic
/// for a given seed). Vertices with a fixed flag stay.
void jitter(HexMesh& mesh, double amplitude, unsigned seed = 1);

}  // namespace isohex
