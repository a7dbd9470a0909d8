#pragma once
/// \file pillow.hpp
/// \brief Sheet insertion by pillowing (Mitchell & Tautges 1995; Shepherd et al. 2006, §4.1.1).
///
/// A *shrink set* is a set of hexes. Its *interface* is the set of quads between a
/// shrink-set hex and a hex outside it, plus — for the boundary variant — the boundary
/// quads of shrink-set hexes. Pillowing splits every interface vertex (in the simple case
/// into the original, kept by the outside, and a copy, taken by the shrink-set hexes and moved
/// a little into the shrink set) and fills the gap with one new hex per interface quad: a new
/// dual sheet parallel to the interface.
///
/// \par Pinches
/// Around an interface vertex v the hexes on each side fall into fans: groups connected
/// through same-side quads that contain v. Each fan gets its own vertex, so two shrink-set
/// hexes touching only at an edge or a vertex are pillowed separately (inner pinch), and so
/// are two outside regions that the shrink set separates at v (outer pinch: the outside fan
/// that does not keep v gets a copy too). Along a pinched edge (four or more interface quads
/// around it) the fans of one side are merged so that the new hexes' side faces pair up; which
/// side is chosen per edge so that every vertex can be placed (pillow_split.hpp). Every
/// non-empty shrink set with an interface is pillowed; none is refused for its shape.
///
/// \par Boundary
/// Interface vertices on the mesh boundary whose fan still has boundary quads at v (the
/// interface reaches the boundary there) keep their copy on the boundary: the copy moves in
/// the boundary's tangent plane only, so the new sheet ends on the boundary. In the boundary
/// variant the boundary quads are themselves interface quads, the original surface vertices
/// stay where they are (only new hexes use them) and the copies go inward: the surface mesh
/// is bit-identical before and after.
///
/// \par Placement
/// One vertex per interface vertex, the *keeper*, keeps v's id and position: the exterior's
/// group (boundary variant), else the group no direction can move, else an outside group. The
/// others move into their side along the area-weighted mean normal of their interface quads
/// (tilted until it sees every quad corner at v) by `offset` × the mean length of their
/// interface edges at v, lengthened by up to 2× at convex corners so that the new layer is
/// `offset` thick measured normal to each quad (a vertex at a cube corner moves along the
/// diagonal by √3·offset·h). Wherever a new hex or a changed old hex would have a scaled
/// Jacobian ≤ 0, the displacements of the moved vertices it uses are halved, repeatedly.
/// Where the interface itself is folded at v (some group sees none of the directions, e.g.
/// inverted boundary quads of a tangled input), its new hexes cannot all be positive; they
/// are counted in `inverted_new_hexes` and left for an untangler.

#include "isohex/mesh/hex_mesh.hpp"

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace isohex {

/// How to pillow.
struct PillowOptions {
  /// Thickness of the new layer as a fraction of the local mean edge length. 0.25 leaves a
  /// shrink-set hex at least half its thickness even where the interface covers two of its
  /// opposite faces (a one-hex-thick shrink set), so halving is rarely needed, while the new
  /// hexes stay within a 4:1 aspect ratio that smoothing can relax afterwards.
  double offset = 0.25;
  /// Also pillow the boundary quads of shrink-set hexes (the sheet then encloses the shrink
  /// set instead of ending on the boundary).
  bool include_boundary = false;
  /// Halvings of a displacement tried before giving up on a vertex. 12 leaves the layer at
  /// least offset·2⁻¹² ≈ 6·10⁻⁵ of the edge length thick: much thinner and Verdict scores the
  /// new hexes as degenerate (relative squared edge length below 2.2·10⁻¹⁵), which is worse
  /// for an untangler than a slightly inverted hex.
  int max_halvings = 12;
  /// The box the new vertices must stay in (a volume's sampled domain): a copy placed outside
  /// it is clamped into it first. Pillowing a solid cut by the box moved the copies of rim
  /// vertices across it (headsq, no optimisation after: 46 vertices outside). Unbounded by default.
  Vec3 domain_lo = Vec3::Constant(-std::numeric_limits<double>::infinity());
  Vec3 domain_hi = Vec3::Constant(std::numeric_limits<double>::infinity());
};

/// What pillow() did.
struct PillowResult {
  HexMesh mesh;                     ///< the pillowed mesh: old vertices and hexes keep their ids
  std::size_t interface_quads = 0;  ///< = new hexes, appended after the old ones
  std::size_t interface_vertices = 0;
  std::size_t pinch_copies = 0;     ///< copies beyond one per interface vertex (pinches)
  std::size_t outside_copies = 0;   ///< copies taken by outside hexes (outer pinches)
  std::size_t pinched_edges = 0;    ///< interface edges whose new side faces needed pairing
  std::size_t flipped_edges = 0;    ///< ... of which the shrink side was merged (see pillow_split.hpp)
  std::size_t folded_vertices = 0;  ///< interface vertices where no placement is positive
  std::size_t inverted_new_hexes = 0;      ///< new hexes with scaled Jacobian <= 0 (only at folded vertices)
  std::size_t inverted_changed_hexes = 0;  ///< old hexes positive before, not after (ditto)
  std::size_t reduced_vertices = 0; ///< copies whose displacement had to be halved
  std::size_t clamped_vertices = 0; ///< copies clamped into PillowOptions' domain box
  double min_new_scaled_jacobian = 1.0;  ///< over the new hexes
  /// Hexes added to / removed from the shrink set where a pinch had no valid placement
  /// (see pillow(); ascending).
  std::vector<Index> added, removed;
  /// Vertex that each new vertex copies: mesh.points[old_num_vertices + i] is a copy of
  /// copy_of[i].
  std::vector<Index> copy_of;
};

/// Pillows `shrink_set` (one flag per hex, nonzero = in the set) of a valid mesh.
/// Throws isohex::Error if the mesh is invalid, the set is empty or has no interface, or the
/// flags do not match the hexes (and, not seen on any test, if the side faces along a pinched
/// edge cannot be paired; the message names the edge).
PillowResult pillow(const HexMesh& mesh, const std::vector<std::uint8_t>& shrink_set,
                    const PillowOptions& options = {});

/// Boundary sheets (§4.1.1): pillows the whole mesh (block < 0) or the hexes of one block,
/// boundary quads included, so that every boundary component is captured by one new sheet.
/// `options` as for pillow() (include_boundary is set here).
PillowResult pillow_boundary(const HexMesh& mesh, Index block = -1, double offset = PillowOptions{}.offset);
PillowResult pillow_boundary(const HexMesh& mesh, Index block, PillowOptions options);

/// A shrink set from a CLI specification: `boundary` (every hex), `block:ID`,
/// `region:EXPR` (hexes whose centroid is inside the implicit shape EXPR, see implicit.hpp)
/// or `ids:FILE` (one hex id per line; blank lines and lines starting with '#' ignored).
/// Throws isohex::Error for an unknown kind, a bad id (naming the file and line) or a bad
/// shape expression.
std::vector<std::uint8_t> shrink_set_from_spec(const HexMesh& mesh, const std::string& spec);

/// True for specs whose sheet should enclose the set, boundary quads included
/// (`boundary`, `block:ID`).
bool spec_includes_boundary(const std::string& spec);

/// Number of hexes with two or more faces on the boundary (each such hex has a boundary
/// edge with a dihedral angle set by one element: the poor-quality situation §3.2 avoids).
std::size_t count_multi_boundary_hexes(const HexMesh& mesh);

}  // namespace isohex
