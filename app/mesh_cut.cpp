// isohex mesh --cut: the cut stage over the pillowed mesh, its report, and the score by which
// (see mesh_stages.hpp).
#include "mesh_stages.hpp"
#include "isohex/mesh/topology.hpp"
#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

namespace isohex::cli {

nlohmann::json cut_step_json(const CutStep& s, double max_distance) {
  return {{"surface", s.surface},
          {"missed", s.missed},
          {"inside_hexes", s.inside_hexes},
          {"outside_hexes", s.outside_hexes},
          {"moved_across", s.moved_across},
          {"sheet_hexes", s.sheet_hexes},
          {"dropped_hexes", s.dropped_hexes},
          {"surface_vertices", s.surface_vertices},
          {"curve_vertices", s.curve_vertices},
          {"corner_vertices", s.corner_vertices},
          {"max_relative_distance", max_distance}};
}

nlohmann::json cut_stage(HexMesh& mesh, std::vector<std::int8_t>& vertex_place, const contour::Region& region,
                         const std::vector<Shape>& shapes, const std::vector<contour::LevelSet>& isosurfaces, CutKeep keep,
                         bool terminal, CutStage& stage, double tie_band) {
  if (terminal) fmt::print("  cutting...\n"), std::fflush(stdout);
  CutOptions co;
  co.keep = keep;
  co.tie_band = tie_band;
  co.boundary = region.surfaces;
  co.domain = region.domain;
  for (const contour::LevelSet& f : contour::box_faces(region.domain)) co.boundary.push_back(f);
  stage.first_cut = static_cast<int>(co.boundary.size());
  co.feature_degrees = 180;  // a scan's boundary has no features: its vertices are on level sets
  std::vector<contour::LevelSet> surfaces;
  const double scale = cut_scale(mesh, co);
  for (const Shape& s : shapes) surfaces.emplace_back(std::make_shared<const Shape>(s), scale);
  surfaces.insert(surfaces.end(), isosurfaces.begin(), isosurfaces.end());
  CutResult r = cut(mesh, surfaces, co);
  nlohmann::json steps = nlohmann::json::array();
  for (std::size_t i = 0; i < r.steps.size(); ++i) {
    const CutStep& c = r.steps[i];
    fmt::print("cut {}: {}: {} hexes inside, {} outside; {} new sheet hexes{}; {} vertices on it ({} on curves, {} at "
               "corners), within {:.3g} of it; optimised near the sheets: min SJ {:.4f}\n",
               i + 1, c.surface, c.inside_hexes, c.outside_hexes, c.sheet_hexes,
               c.dropped_hexes ? fmt::format(", {} dropped", c.dropped_hexes) : "", c.surface_vertices, c.curve_vertices,
               c.corner_vertices, r.max_distance[i], c.optimisation.worst.min_sj_after);
    steps.push_back(cut_step_json(c, r.max_distance[i]));
    steps.back()["surface_quads"] = r.surface_quads[i].size();
  }
  // The places the later stages read: boundary vertices on a region surface or the box.
  std::vector<std::uint8_t> on_boundary(r.mesh.points.size(), 0);
  for (const Quad& q : boundary_quads(r.mesh))
    for (Index v : q) on_boundary[v] = 1;
  vertex_place.assign(r.mesh.points.size(), contour::kInteriorVertex);
  for (std::size_t v = 0; v < vertex_place.size(); ++v) {
    if (!on_boundary[v]) continue;
    for (std::size_t k = 0; k < region.surfaces.size() && vertex_place[v] == contour::kInteriorVertex; ++k)
      if (region.surfaces[k].on(r.mesh.points[v])) vertex_place[v] = static_cast<std::int8_t>(k);
    if (vertex_place[v] == contour::kInteriorVertex && co.boundary.size() > region.surfaces.size())
      for (std::size_t k = region.surfaces.size(); k < co.boundary.size(); ++k)
        if (co.boundary[k].on(r.mesh.points[v])) vertex_place[v] = contour::kBoxVertex;
  }
  stage.before = std::move(mesh);
  stage.surfaces = std::move(r.surfaces);
  stage.constraints = std::move(r.constraints);
  mesh = std::move(r.mesh);
  return {{"keep", cut_keep_name(keep)}, {"cuts", steps}};
}

void report_cut_distances(const CutStage& stage, const HexMesh& mesh, nlohmann::json& cutting) {
  for (std::size_t j = 0; j + static_cast<std::size_t>(stage.first_cut) < stage.surfaces.size(); ++j) {
    const int id = stage.first_cut + static_cast<int>(j);
    const contour::LevelSet& s = stage.surfaces[static_cast<std::size_t>(id)];
    double far = 0;
    std::size_t n = 0;
    for (std::size_t v = 0; v < stage.constraints.size(); ++v)
      if (stage.constraints[v].first == id || stage.constraints[v].second == id) {
        far = std::max(far, std::abs(s.level(mesh.points[v])) / s.scale());
        ++n;
      }
    fmt::print("cut {}: {} vertices on it after the optimisation, within {:.3g} of it (relative to {})\n", j + 1, n,
               far, s.field() ? "the volume's value range" : "the mesh's diagonal");
    cutting["cuts"][j]["final_max_relative_distance"] = far;
  }
}

}  // namespace isohex::cli
