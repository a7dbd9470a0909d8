#pragma once
/// \file cut.hpp
/// \brief Cutting a hex mesh along a surface by sheet insertion (§4.2 of Shepherd et al. 2006;
/// Borden, Shepherd & Benzley's mesh cutting).
///
/// A cut surface S is an implicit shape (volume/implicit.hpp; inside where its distance is
/// negative). One cut:
/// 1. The hexes are split into two sides by the sign at their centroids; a hex with four or
///    more faces towards the other side (a lone spike of the staircase) joins that side, until
///    none is left.
/// 2. A sheet is pillowed into each side that is kept (pillow.hpp): the interface vertices
///    then belong to the new hexes alone, and every hex next to the interface is a new one
///    with exactly one face on it, so the staircase can be moved onto S without flattening
///    any hex.
/// 3. The interface vertices go onto S; where the interface meets the mesh's boundary, onto
///    the curve where S meets the boundary (the string of edges at the crease); where it
///    meets a feature edge of the boundary or an earlier cut's crease, onto the point where
///    the three meet. The copies that pillowing moved off the boundary go back onto it.
/// 4. Keep both sides (the inside becomes a new block; the interface is conforming: the same
///    quads on both sides) or drop one.
/// 5. Untangle, optimise the mean ratio and raise the worst hexes near the new sheets only,
///    each vertex kept on what it lies on: a cut surface, the input's boundary (its
///    triangles), their curve; corners fixed.
/// Cuts apply one after another; an earlier cut's vertices stay on its surface.

#include "isohex/contour/region.hpp"
#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/volume/implicit.hpp"

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace isohex {

/// Which side of each cut stays.
enum class CutKeep : unsigned char {
  both,     ///< both sides, the inside as a new block
  inside,   ///< the inside of the shape (an intersection with it)
  outside,  ///< the outside (a difference: the shape carved away)
};
std::string_view cut_keep_name(CutKeep k);
std::optional<CutKeep> cut_keep_from_name(std::string_view name);

/// How to cut.
struct CutOptions {
  CutKeep keep = CutKeep::both;
  /// Thickness of each new sheet, as PillowOptions::offset.
  double offset = 0.25;
  /// Boundary quads meeting at more than this many degrees are on a feature edge of the
  /// input: the vertices there keep to both faces (the edge), or are fixed at a corner.
  double feature_degrees = 30;
  /// Optimise after each cut (untangle, shape, worst pass) the vertices within `rings` hex
  /// rings of the new sheets; the rest of the mesh is held.
  bool optimize = true;
  int rings = 3;
  /// The optimisers' options (their `surface`, `incidence` and the fixed vertices are set by cut()).
  OptimizeOptions optimize_options;
  /// Unit of relative distances (0: the input's bounding-box diagonal); the cut surfaces'
  /// tolerance is 1e-10 of it.
  double scale = 0;
  /// The surfaces the input's boundary lies on, as level sets (e.g. `isohex mesh`'s isosurface
  /// and the faces of its domain box): a boundary vertex on some of them (LevelSet::on) keeps
  /// to those exactly, so a crease lies on the isosurface itself; the other boundary vertices
  /// (and all of them when this is empty) keep to the input's boundary quads (as triangles).
  std::vector<contour::LevelSet> boundary;
  /// A surface that misses the mesh (every hex on one side) is skipped (CutStep::missed)
  /// instead of an error.
  bool skip_missing = false;
  /// No vertex is placed outside this box (`isohex mesh`: the volume's domain, past whose faces
  /// an isosurface goes on): an interface vertex whose place would lie outside sends its hexes
  /// to one side, as one that cannot be placed does.
  std::optional<Aabb> domain;
  /// A hex whose centre lies within `tie_band` × its mean edge length of a cut surface counts as
  /// outside it, as one exactly on it does (0: the sign alone). Where the surface runs through
  /// the middle of a layer of hexes that smoothing moved a little, the signs there are noise and
  /// the interface zigzags between the layer's two faces; a tie band takes one face of it
  /// (`isohex mesh --cut` cuts again with 0.05 when the first cut leaves hexes below 0.2).
  double tie_band = 0;
  ProgressCallback progress;
};

/// What one cut did.
struct CutStep {
  std::string surface;              ///< the shape, as text
  std::size_t inside_hexes = 0, outside_hexes = 0;  ///< of the mesh before the cut, after cleaning
  std::size_t moved_across = 0;     ///< hexes that changed side in the cleaning
  std::size_t sheet_hexes = 0;      ///< new hexes (both sheets)
  std::size_t dropped_hexes = 0;    ///< removed with the side not kept
  std::size_t surface_vertices = 0; ///< vertices on the cut surface (curve and corner ones included)
  std::size_t curve_vertices = 0;   ///< ... on its curve with the boundary or with another cut
  std::size_t corner_vertices = 0;  ///< ... where three surfaces meet (fixed)
  std::size_t unplaced = 0;         ///< vertices whose projection failed (left where they were)
  bool missed = false;              ///< the surface misses the mesh (CutOptions::skip_missing)
  bool optimized = false;
  OptimizeResult optimisation;
};

/// The result.
struct CutResult {
  /// The cut mesh; its face_sets hold each cut's faces: "cutJ" where the surface is boundary (a
  /// side dropped), "cutJ_inside" and "cutJ_outside" (the faces of the hexes on either side)
  /// where it is an interface, J = 1, 2, ... in the order of the surfaces.
  HexMesh mesh;
  std::vector<CutStep> steps;
  /// Per cut surface: the quads on it in `mesh` (each once; for `both`, oriented from the inside
  /// side to the outside), for side sets.
  std::vector<std::vector<Quad>> surface_quads;
  /// Per cut surface: the largest |distance| of a vertex on it to it, relative to the scale.
  std::vector<double> max_distance;
  /// CutOptions::boundary followed by the cut surfaces, and per vertex of `mesh` what it keeps
  /// to among them (BoundarySurface::kTriangles: the input's boundary quads): for optimising the
  /// cut mesh further with BoundarySurface(mesh, input, surfaces, constraints).
  std::vector<contour::LevelSet> surfaces;
  std::vector<BoundarySurface::Constraint> constraints;
};

/// The unit of a cut's relative distances: CutOptions::scale, or the diagonal of `mesh`'s
/// bounding box (the scale cut() gives the LevelSets of shapes). Throws for an empty mesh.
double cut_scale(const HexMesh& mesh, const CutOptions& options);

/// Cuts `mesh` (a valid hex mesh) by each surface in turn. Throws isohex::Error for an invalid
/// mesh, a surface that misses it (every hex on one side) or a kept side that would be empty.
CutResult cut(const HexMesh& mesh, const std::vector<Shape>& surfaces, const CutOptions& options = {});

/// The same for surfaces given as level sets, positive inside (contour::LevelSet: a shape's, or
/// an isosurface of a volume: a material interface inside a mesh, the two materials conforming
/// blocks where each is several cells thick). The cut vertices go onto |L| <= the level set's
/// tolerance (1e-7 of an isosurface's value range); CutResult::max_distance is |L| / its scale().
CutResult cut(const HexMesh& mesh, const std::vector<contour::LevelSet>& surfaces, const CutOptions& options = {});

}  // namespace isohex
