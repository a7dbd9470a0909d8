#pragma once
/// \file refine_boundary.hpp
/// \brief Adaptive refinement of an extracted mesh where its boundary quads chord the
/// isosurface too deeply (LBIE-Mesher's adaptive stage: finer hexes by templates, no hanging
/// nodes, the new boundary vertices placed on the isosurface).
///
/// One vertex per grid cell puts the dual-contouring quads' corners on the isosurface but
/// their interiors a chord below it on convex parts (above it on concave ones): the enclosed
/// volume is off by the chord depth times the area, about 1.5 % on small molecules at one
/// voxel per cell. Refining the hexes under the deep quads by 3 (isohex::refine, conforming
/// transition templates around them) and projecting every new boundary vertex onto its
/// surface cuts the chord depth there about ninefold, without refining the interior.

#include "isohex/contour/dual_contour.hpp"
#include "isohex/contour/region.hpp"

#include <cstddef>
#include <vector>

namespace isohex::contour {

struct BoundaryRefineOptions {
  /// A boundary quad is too coarse when a point of it (centre, edge midpoints) is farther than
  /// `chord_tolerance` × h from its surface (h: the extraction's cell size).
  double chord_tolerance = 0.02;
  /// Rounds of refinement; each round measures the quads again with the same absolute
  /// tolerance (a quad refined once is h/3 across).
  int levels = 1;
  /// A coarse quad is refined only if the templates' promotion (refine.hpp) then marks at most
  /// this many vertices beyond its corners; otherwise refining it would spread far beyond it.
  std::size_t promotion_budget = 8;
};

struct BoundaryRefineReport {
  int levels = 0;                        ///< rounds that refined something
  std::size_t hexes_before = 0, hexes_after = 0;
  std::size_t coarse_quads = 0;          ///< quads over the tolerance, first round
  std::size_t refined_quads = 0;         ///< of the coarse quads (all rounds), those refined within the budget
  std::size_t unreachable_quads = 0;     ///< quads with a point farther than h from the surface: not refined
  std::size_t coarse_quads_after = 0;    ///< quads over the tolerance after the last round
  std::size_t marked_vertices = 0;       ///< marked for refinement (promotion included), all rounds
  std::size_t promoted_vertices = 0;     ///< of those, marked by the templates' rules beyond the quads' corners
  std::size_t projected_vertices = 0;    ///< new boundary vertices moved onto their surface
  std::size_t projection_failures = 0;   ///< of those, left where the templates put them
  double max_chord_before = 0;           ///< deepest chord / h before
  double max_chord_after = 0;            ///< deepest chord / h after
  double mean_chord_before = 0;          ///< area-weighted mean chord / h before (quads on a surface)
  double mean_chord_after = 0;           ///< the same after
  double seconds = 0;
};

/// How far boundary quad `q` strays from surface `s`: the longest way its centre and edge
/// midpoints travel when projected onto it (world units), or -1 if one of them does not reach
/// it within `max_distance`.
double quad_chord(const LevelSet& s, const HexMesh& mesh, const Quad& q, double max_distance);

/// Refines `extracted` (mesh and vertex_place) where its boundary quads on a surface of
/// `region` chord it deeper than the tolerance. Vertices of quads on the domain box are left
/// as they are (the box is flat). The result is conformal, with the same boundary topology;
/// it is the same for any thread count.
BoundaryRefineReport refine_boundary(const Region& region, ExtractResult& extracted, const BoundaryRefineOptions& options);

}  // namespace isohex::contour
