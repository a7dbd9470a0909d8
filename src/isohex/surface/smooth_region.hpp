#pragma once
/// \file smooth_region.hpp
/// \brief Surface smoothing of a mesh fresh from extraction: every isosurface of its region
/// in turn, with the domain box's faces smoothed in their planes.

#include "isohex/contour/dual_contour.hpp"
#include "isohex/contour/region.hpp"
#include "isohex/surface/smooth_surface.hpp"

#include <cstddef>
#include <functional>
#include <vector>

namespace isohex {

/// Runs smooth_surface() on `extracted.mesh` once per surface of `region` that is an
/// isosurface (an analytic sphere's vertices are exact already: its report stays empty),
/// with `options` except for the masks, which come from `extracted.vertex_place`: the
/// vertices of the other surfaces are pinned, so each surface keeps its own vertices on it;
/// vertices on one face of the domain box slide in that face (SurfaceSmoothingOptions::planar),
/// along the rim where it meets the isosurface; those on the box's edges are pinned.
/// `on_surface(k)` is called before surface k. Returns one report per surface.
std::vector<SurfaceSmoothingReport> smooth_region_surfaces(const contour::Region& region,
                                                           contour::ExtractResult& extracted,
                                                           const SurfaceSmoothingOptions& options,
                                                           const std::function<void(std::size_t)>& on_surface = {});

}  // namespace isohex
