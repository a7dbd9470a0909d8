#include "mesh_stages.hpp"

#include "isohex/contour/dual_contour.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/report.hpp"
#include "isohex/sheets/pillow.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <sys/resource.h>

namespace isohex::cli {

StageRow stage_row(const std::string& name, const HexMesh& mesh, double seconds) {
  StageRow r{name, mesh.num_hexes(), mesh.num_vertices(), scaled_jacobians(mesh), {}, seconds, nlohmann::json::object()};
  r.sj = summarize(HexMetric::scaled_jacobian, r.sj_values, 0);
  return r;
}

nlohmann::json pillow_stage(HexMesh& mesh, std::vector<std::int8_t>& vertex_place, bool terminal) {
  if (terminal) fmt::print("  pillowing...\n"), std::fflush(stdout);
  PillowResult p = pillow_boundary(mesh);
  fmt::print("pillowing: {} new hexes (one per boundary quad), {} new vertices, min SJ of the new hexes {:.4g}\n",
             p.interface_quads, p.mesh.num_vertices() - mesh.num_vertices(), p.min_new_scaled_jacobian);
  // Old vertices keep their ids (the boundary among them); the copies are interior.
  vertex_place.resize(static_cast<std::size_t>(p.mesh.num_vertices()), contour::kInteriorVertex);
  nlohmann::json j = {{"new_hexes", p.interface_quads},
                      {"new_vertices", p.mesh.num_vertices() - mesh.num_vertices()},
                      {"pinch_copies", p.pinch_copies},
                      {"min_new_sj", p.min_new_scaled_jacobian}};
  mesh = std::move(p.mesh);
  return j;
}

nlohmann::json optimise_stage(HexMesh& mesh, bool terminal, std::size_t& inverted_left) {
  const std::vector<std::uint8_t> fixed = fixed_mask(mesh, FixedVertices::boundary);
  ProgressCallback progress;
  if (terminal)
    progress = [](const IterationReport& r) {
      fmt::print("  {:<8} {:>4}  objective {:.6g}  min SJ {:.4f}  inverted {}\n", r.stage, r.iteration, r.objective,
                 r.min_sj, r.inverted);
      std::fflush(stdout);
    };
  nlohmann::json j;
  UntangleOptions uo;
  uo.progress = progress;
  const UntangleResult u = untangle(mesh, fixed, uo);
  fmt::print("untangle: {} iterations, min SJ {:.4f}, inverted {}{}\n", u.iterations, u.min_sj, u.inverted,
             u.infeasible.empty() ? "" : fmt::format(" ({} hexes cannot be valid with the boundary fixed)", u.given_up.size()));
  j["untangle"] = {{"iterations", u.iterations}, {"min_sj", u.min_sj}, {"inverted", u.inverted},
                   {"reached_margin", u.reached_margin}, {"given_up", u.given_up}};
  ShapeOptions so;
  so.progress = progress;
  const ShapeResult s = optimize_shape(mesh, fixed, so);
  fmt::print("shape: {} sweeps, mean inverse mean ratio {:.6f} -> {:.6f}\n", s.iterations, s.objective_before,
             s.objective_after);
  j["shape"] = {{"iterations", s.iterations}, {"objective_before", s.objective_before},
                {"objective_after", s.objective_after}};
  WorstOptions wo;
  wo.progress = progress;
  const WorstResult w = improve_worst(mesh, fixed, wo);
  fmt::print("worst: {} passes, {} moves, min SJ {:.4f} -> {:.4f}\n", w.passes, w.moves, w.min_sj_before, w.min_sj_after);
  j["worst"] = {{"passes", w.passes}, {"moves", w.moves}, {"min_sj_before", w.min_sj_before},
                {"min_sj_after", w.min_sj_after}};
  inverted_left = u.inverted;
  return j;
}

void print_stage_table(const std::vector<StageRow>& rows) {
  fmt::print("\n{:<18} {:>10} {:>10} {:>8} {:>8} {:>9} {:>9} {:>9}\n", "stage", "hexes", "vertices", "min SJ", "mean SJ",
             "SJ < 0", "SJ < 0.2", "time (s)");
  for (const StageRow& r : rows)
    fmt::print("{:<18} {:>10} {:>10} {:>8.4f} {:>8.4f} {:>9} {:>9} {:>9.2f}\n", r.name, r.hexes, r.vertices, r.sj.min,
               r.sj.mean, r.sj.inverted + r.sj.degenerate, r.sj.inverted + r.sj.degenerate + r.sj.questionable,
               r.seconds);
}

nlohmann::json stage_table_json(const std::vector<StageRow>& rows) {
  nlohmann::json a = nlohmann::json::array();
  for (const StageRow& r : rows)
    a.push_back({{"stage", r.name},
                 {"hexes", r.hexes},
                 {"vertices", r.vertices},
                 {"scaled_jacobian", to_json(r.sj)},
                 {"below_0.2", r.sj.inverted + r.sj.degenerate + r.sj.questionable},
                 {"seconds", r.seconds}});
  return a;
}

void write_mesh_report(const std::string& dir, const std::string& title, const std::vector<StageRow>& rows,
                       const nlohmann::json& summary, const HexMesh& mesh) {
  ReportInput in;
  in.title = title;
  in.summary = summary;
  in.mesh = &mesh;
  for (const StageRow& r : rows)
    in.stages.push_back({r.name, r.sj_values, static_cast<std::size_t>(r.hexes), static_cast<std::size_t>(r.vertices),
                         r.seconds, r.extra});
  write_report(dir, in);
}

double peak_memory_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // Linux: KiB
}

}  // namespace isohex::cli
