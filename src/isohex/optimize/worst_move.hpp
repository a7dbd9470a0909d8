#pragma once
/// \file worst_move.hpp
/// \brief Internal to optimize/: the worst pass's move of one vertex (worst.cpp runs it).

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"

#include <array>
#include <vector>

namespace isohex::opt {

// Degenerate (collapsed) hexes rank below every real value; a hex that is not certified valid
// inside counts as 0 at best, whatever its nine samples say.
inline double worst_sj_value(const std::array<Vec3, 8>& p) {
  const double v = certified_scaled_jacobian(p);
  return is_degenerate(v) ? -2.0 : v;
}

/// One max–min move of vertex v (see worst_move.cpp): true, with v at its new place, when it
/// found a gain. It reads the places of the vertices of the hexes around v, `start`, the
/// surface and `mesh_min`, and writes only v's place.
bool worst_move(HexMesh& mesh, const Incidence& inc, Index v, const std::vector<Vec3>& start,
                const BoundarySurface* surface, const WorstOptions& options, double mesh_min);

}  // namespace isohex::opt
