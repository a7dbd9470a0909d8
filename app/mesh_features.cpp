// `isohex mesh --shape EXPR --features sheets`: a CSG shape meshed by cuts, every crease on a
// string of edges (sheets/csg_cuts.hpp), instead of sampling it and contouring.
#include "commands.hpp"
#include "mesh_stages.hpp"

#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/validate.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/summary.hpp"
#include "isohex/sheets/csg_cuts.hpp"

#include <fmt/format.h>

#include <chrono>

namespace isohex::cli {

nlohmann::json mesh_shape_by_cuts(const std::string& expression, double cell_size, int resolution,
                                  const std::string& output, bool keep_values, std::vector<StageRow>& rows,
                                  std::size_t& inverted_left) {
  const auto t0 = std::chrono::steady_clock::now();
  const Shape shape = parse_shape(expression);
  CsgMeshOptions opt;
  opt.cell_size = cell_size;
  if (resolution > 0) opt.resolution = resolution;
  const CsgMeshResult r = mesh_by_cuts(shape, opt);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  fmt::print("shape: {}\ngrid: {} hexes; {} smooth pieces to cut along ({} faces of the grid's box skipped)\n", expression,
             r.grid_hexes, r.pieces.size(), r.skipped_faces);
  nlohmann::json pieces = nlohmann::json::array();
  for (std::size_t i = 0; i < r.pieces.size(); ++i) {
    const CutStep& s = r.steps[i];
    if (s.missed) fmt::print("  {}: misses the grid\n", s.surface);
    else
      fmt::print("  {}: {} sheet hexes, {} vertices on it ({} on curves, {} at corners), within {:.3g} of it\n", s.surface,
                 s.sheet_hexes, s.surface_vertices, s.curve_vertices, s.corner_vertices, r.max_distance[i]);
    pieces.push_back(cut_step_json(s, r.max_distance[i]));
  }
  fmt::print("dropped {} hexes outside the shape\n", r.dropped_hexes);
  rows.push_back(stage_row("cuts", r.mesh, seconds, keep_values));
  const ValidationReport check = validate(r.mesh);
  std::vector<double> sj = scaled_jacobians(r.mesh);
  MeshJacobians jacobians = mesh_jacobians(r.mesh);
  const MetricSummary q = summarize(HexMetric::scaled_jacobian, sj);
  const ValiditySummary validity = summarize_validity(jacobians);
  fmt::print("mesh: {} hexes, {} vertices, {} boundary quads, {}\n", r.mesh.num_hexes(), r.mesh.num_vertices(),
             check.num_boundary_quads, check.valid() ? "valid" : "NOT VALID");
  fmt::print("  scaled Jacobian: min {:.4f}  mean {:.4f}\n  inverted (< 0): {}   questionable (< 0.2): {}   degenerate: {}\n",
             q.min, q.mean, q.inverted, q.questionable, q.degenerate);
  fmt::print("  {}\n", describe(validity));
  write_result(output, r.mesh, io::quality_fields(std::move(sj), std::move(jacobians.ratio)));
  inverted_left = q.inverted + q.degenerate;
  return {{"features", "sheets"},
          {"pieces", pieces},
          {"grid_hexes", r.grid_hexes},
          {"skipped_faces", r.skipped_faces},
          {"dropped_hexes", r.dropped_hexes},
          {"hexes", r.mesh.num_hexes()},
          {"vertices", r.mesh.num_vertices()},
          {"valid", check.valid()},
          {"scaled_jacobian", to_json(q)},
          {"validity", to_json(validity)},
          {"seconds", seconds}};
}

}  // namespace isohex::cli
