#include "isohex/surface/smooth_region.hpp"

namespace isohex {

std::vector<SurfaceSmoothingReport> smooth_region_surfaces(const contour::Region& region,
                                                           contour::ExtractResult& extracted,
                                                           const SurfaceSmoothingOptions& options,
                                                           const std::function<void(std::size_t)>& on_surface) {
  const std::vector<std::int8_t>& place = extracted.vertex_place;
  std::vector<std::int8_t> planar = box_face_axes(extracted.mesh, region.domain.lo, region.domain.hi);
  for (std::size_t v = 0; v < planar.size(); ++v)
    if (place[v] != contour::kBoxVertex) planar[v] = -1;
  std::vector<SurfaceSmoothingReport> reports;
  for (std::size_t k = 0; k < region.surfaces.size(); ++k) {
    const IsoField* field = region.surfaces[k].field();
    if (!field) {
      reports.emplace_back();
      continue;
    }
    if (on_surface) on_surface(k);
    SurfaceSmoothingOptions opt = options;
    opt.pinned.assign(extracted.mesh.points.size(), 0);
    for (std::size_t v = 0; v < place.size(); ++v)
      opt.pinned[v] = (place[v] == contour::kBoxVertex && planar[v] < 0) ||
                      (place[v] >= 0 && place[v] != static_cast<std::int8_t>(k));
    opt.planar = planar;
    reports.push_back(smooth_surface(extracted.mesh, *field, opt));
  }
  return reports;
}

}  // namespace isohex
