#pragma once
/// \file refine.hpp
/// \brief Conforming local refinement without hanging nodes: 3-refinement transition
/// templates on marked vertices (Schneiders; Ito, Shih & Soni 2009).
///
/// Each hex is replaced according to which of its corners are marked. Every new point is a
/// point of the hex's parametric lattice, placed by the hex's trilinear map; points on a
/// hex's faces and edges lie on the 1/3 lattice, and the few interior points of the face
/// template on the 1/6 lattice. A face is subdivided by its own marked corners only, so the
/// two hexes sharing it produce the same sub-quads:
/// - no marked corner: unsplit;
/// - one: a small square at that corner and two quads meeting along the diagonal to the
///   opposite corner (3 quads);
/// - two on one edge: three small squares along that edge and four quads going 3 -> 1;
/// - four: 3 x 3.
///
/// Templates (hexes; min scaled Jacobian on the unit cube): corner (1 marked vertex: 4; 0.577),
/// edge (2 marked on an edge: 11; 0.408), face (4 marked on a face: 22; 0.316), full (all 8
/// marked: 27 cubes; 1). Any other configuration is *promoted* first: a set inside one face
/// becomes that face, anything else all 8; repeated over the mesh to the least fixpoint
/// (promotion is monotone, so the result does not depend on the order of the sweep).
///
/// Output order is deterministic: the original vertices keep their ids, parents are visited
/// in order, children in template order, and new vertices numbered by first use. A new
/// vertex is identified by its canonical key (the vertices of its parent edge, face or hex
/// with their trilinear weights, sorted by id), identical from every hex that shares it; its
/// position is the weighted sum in that order, so it is bit-identical from either side.

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/mesh/topology.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace isohex {

/// The refinement templates.
enum class RefineTemplate : std::uint8_t { keep, corner, edge, face, full };
inline constexpr int kNumRefineTemplates = 5;

/// Short name: "unrefined", "corner", "edge", "face", "full".
const char* refine_template_name(RefineTemplate t);

/// The result of refine().
struct RefineResult {
  HexMesh mesh;                        ///< the refined mesh (blocks inherited from the parent)
  std::vector<Index> parent_hex;       ///< per hex of `mesh`, the hex of the input it came from
  /// The input vertices each new vertex is a weighted sum of (those with a nonzero weight,
  /// ascending): for new vertex v (id ≥ the input's vertex count n), source_ids[
  /// source_offsets[v − n] .. source_offsets[v − n + 1]). Two ids: on an input edge; four: on
  /// an input quad; more: inside an input hex. Callers use it to tell which surface a new
  /// boundary vertex lies on.
  std::vector<Index> source_offsets{0};
  std::vector<Index> source_ids;
  std::vector<std::uint8_t> marked;    ///< per input vertex, marked after promotion
  std::size_t marked_vertices = 0;     ///< vertices marked on input
  std::size_t promoted_vertices = 0;   ///< vertices marked by promotion
  /// Number of input hexes refined by each template (indexed by RefineTemplate).
  std::array<std::size_t, kNumRefineTemplates> parents{};
  /// Number of output hexes made by each template.
  std::array<std::size_t, kNumRefineTemplates> children{};
};

/// Refines `mesh` around `marked_vertices` (one flag per vertex, nonzero = marked).
///
/// Fixed flags: a new vertex is fixed when it lies on a boundary edge or boundary quad of the
/// input whose vertices are all fixed (a fixed boundary patch stays fixed once refined);
/// vertices inside hexes are never fixed. Throws isohex::Error if the flag count differs
/// from the vertex count. The mesh should be valid (validate.hpp); the result then is too.
RefineResult refine(const HexMesh& mesh, std::vector<std::uint8_t> marked_vertices);

/// Flags marking the 8 vertices of each hex in `hex_ids` (all ids must be in range).
std::vector<std::uint8_t> marked_vertices_of(const HexMesh& mesh, const std::vector<Index>& hex_ids);

/// The smallest valid configuration containing `corner_mask` (bit c = VTK corner c marked).
std::uint8_t promoted_mask(std::uint8_t corner_mask);

/// Promotes the marks around `seeds` (vertices just marked) until every hex around a marked
/// vertex has a template configuration: the least such superset, whatever the order, since
/// promotion is monotone. `around` is vertex_hexes(mesh). Returns the number of vertices it
/// marked; if that would exceed `limit`, it unmarks them again (not the seeds) and returns
/// limit + 1. refine() runs it on all marks without a limit.
std::size_t close_marks(const HexMesh& mesh, const Incidence& around, std::vector<std::uint8_t>& marked,
                        std::vector<Index> seeds, std::size_t limit = static_cast<std::size_t>(-2));

/// The template of a valid configuration (promoted_mask(m) == m).
RefineTemplate template_of(std::uint8_t corner_mask);

/// A sub-hex in parametric lattice coordinates: sixths of the parent, {0..6}^3, VTK order.
using LatticeHex = std::array<std::array<int, 3>, 8>;

/// The sub-hexes for a valid configuration, positively oriented, in output order: the
/// canonical template mapped by the cube symmetry that takes it onto `corner_mask`.
const std::vector<LatticeHex>& template_hexes(std::uint8_t corner_mask);

}  // namespace isohex
