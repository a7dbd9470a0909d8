#pragma once
/// \file patch.hpp
/// \brief Internal to optimize/: joint max–min moves of a patch of vertices, the worst pass's
/// end game.
///
/// One vertex at a time, a max–min ascent stops where raising the smallest term needs two
/// vertices to move together: a term of vertex a ties with a term of vertex b, and either one
/// moving alone lowers the other's (the coordinate-wise optimum of a nonsmooth function is not
/// its optimum). cthead's bone at iso 1200, h 5 kept a pillow hex at 0.170 and ratios of 0.05
/// through 100 passes of 60 moves each that changed nothing. The patch's LP linearises every
/// term of every hex around the patch in all its vertices at once.

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"

#include <vector>

namespace isohex::opt {

/// Moves the free vertices `patch` (ascending, none fixed) together for the hexes `targets`
/// (ascending): the smallest of their weighted Bernstein ratio terms and scaled-Jacobian frames
/// below the floor that the patch changes must rise; the other frames are held above the floor,
/// the other hexes' ratio terms at their value (a max–min over the whole patch would stop at the
/// first term of another hex that cannot rise), under
/// the same guards as the worst pass's single moves (no valid hex inverted, no more hexes below
/// 0.2 around them, the certified scaled Jacobian not below the higher of options.sj_floor and
/// `mesh_min`, the ratio bound and the edge ratios within WorstOptions' limits, no edge shorter
/// than min_edge_shrink of its length in `start`). Sliding vertices step in their tangent plane
/// and are put back on their surface, loose ones into their band. True if the patch moved.
///
/// The guarded model: the LP also keeps the guards' ratio floor (the ratio terms at or above
/// it held there, and near it the other hexes' largest coefficients held down, since the bound
/// is min / max), and the hexes' own frames below options.sj_floor rise even where one is the
/// patch's minimum. Stricter, so tried where the plain model's steps are refused: ECR block_in
/// with its boundary fixed, every ratio pressed to the 0.2 floor, where the plain LP's every
/// step lowered a ratio below it.
///
/// `both` (the worst pass's): the plain model, and where it gains nothing the guarded one,
/// unless that is the same LP (no caps, the same frames rising, every row held at the same
/// level), which would take the same steps and fail the same way.
enum class PatchModels { plain, guarded, both };
bool move_patch(HexMesh& mesh, const Incidence& inc, const std::vector<Index>& targets, const std::vector<Index>& patch,
                const std::vector<Vec3>& start, const WorstOptions& options, double mesh_min,
                PatchModels models = PatchModels::plain);

}  // namespace isohex::opt
