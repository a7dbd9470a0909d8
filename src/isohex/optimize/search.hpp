#pragma once
/// \file search.hpp
/// \brief Internal to optimize/: a random local search, the worst pass's last resort.
///
/// The max–min moves (one vertex, or a patch by one LP) climb along the linearised terms and
/// stop at a point where no step of the model gains: a Clarke-stationary point of a nonsmooth
/// max–min, which is not its maximum. cthead's bone at iso 1200, h 5 kept four pillow hexes at a
/// jacobian ratio of 0.052 round a core hex squeezed to 1 mm; neither the single moves nor the
/// joint ones changed them, while an independent hill climb on the true values (random steps,
/// any that keeps every hex at or above the current minimum taken) lifted the same region to
/// a rank of 0.22. Such a walk moves sideways across the level set of the minimum, which the
/// ascent never does.

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/optimize.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace isohex::opt {

/// What search_region() did.
struct SearchOutcome {
  std::size_t trials = 0, accepted = 0;
  std::vector<Index> vertices;   ///< the vertices the walk may have moved (ascending)
  double before = 0, after = 0;  ///< the region's smallest rank (hex_rank()) before and after
};

/// A random walk of the free vertices within options.search_rings vertex rings of the hexes
/// `cluster` (at most options.search_vertices of them): one vertex at a time steps by a
/// Gaussian of a fraction of its mean edge (the fraction adapted to the acceptance rate;
/// sliding vertices in their tangent plane, put back on the surface, loose ones into their
/// band), and the step is taken when no hex around the vertex falls below the smallest rank of
/// the region now, and each keeps the worst pass's guards against its own value when the
/// search began: certified scaled Jacobian not below the lower of that and the higher of
/// options.sj_floor and `mesh_min`, ratio bound not below the lower of that and
/// options.ratio_floor, edge ratio not above the higher of that and options.max_edge_ratio (no
/// exception for poor ratios), no edge at the vertex shorter than min_edge_shrink of its
/// length in `start`. Half of the steps go to vertices of the region's worst hexes. It stops
/// at options.search_trials steps, when every hex of the region reaches a rank of 0.2, or when
/// the minimum has not risen for a quarter of the budget; without a gain the vertices go back
/// where they were. Sequential with a fixed seed: the same mesh gives the same result.
/// Hexes marked in `held` (the members of find_quality_bounds()' sets, which the fixed
/// vertices keep below 0.2) do not count in the minimum: each only keeps the lower of its own
/// rank and the minimum, so a hex proven stuck does not stop the walk round its neighbours.
SearchOutcome search_region(HexMesh& mesh, const Incidence& inc, const std::vector<std::uint8_t>& fixed,
                            const std::vector<Index>& cluster, const std::vector<Vec3>& start,
                            const WorstOptions& options, double mesh_min,
                            const std::vector<std::uint8_t>& held = {});

}  // namespace isohex::opt
