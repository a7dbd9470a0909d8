// isohex smooth IN -o OUT: untangle, then optimise shape (inverse mean ratio), then raise the
// worst elements, with boundary / file-given / no vertices fixed.
#include "commands.hpp"

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/summary.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <ostream>
#include <unistd.h>

namespace isohex::cli {

namespace {

struct Args {
  std::string in, out, json;
  bool untangle = false, skip_non_hex = false, no_worst = false, slide = false;
  double feature_angle = 30;
  FixedVertices fixed = FixedVertices::boundary;
  int max_iter = 100;
  double tol = 1e-5, margin = 0.05;
  int* threads = nullptr;
};

MetricSummary sj_summary(const HexMesh& mesh) {
  return summarize(HexMetric::scaled_jacobian, scaled_jacobians(mesh), 5);
}

void print_quality(const char* label, const MetricSummary& s) {
  fmt::print("{:<7} scaled Jacobian: min {:.4f}  mean {:.4f}  inverted (< 0): {}  below {}: {}\n", label, s.min, s.mean,
             s.inverted, kQuestionableSJ, s.inverted + s.questionable + s.degenerate);
}

nlohmann::json quality_json(const MetricSummary& s) {
  return {{"min", s.min},
          {"mean", s.mean},
          {"inverted", s.inverted},
          {"below_0.2", s.inverted + s.questionable + s.degenerate},
          {"degenerate", s.degenerate}};
}

void run(const Args& a) {
  ThreadLimit limit(*a.threads);
  const auto t0 = std::chrono::steady_clock::now();
  if (a.slide && a.fixed != FixedVertices::boundary)
    throw Error("smooth: --boundary slide moves the boundary vertices; it needs --fixed boundary (the default)");
  HexMesh mesh = load_mesh(a.in, a.skip_non_hex);
  // With --boundary slide the boundary vertices move on the input's own boundary surface,
  // except those on sharp feature edges (pinned): only those are fixed.
  std::unique_ptr<BoundarySurface> surface;
  if (a.slide) surface = std::make_unique<BoundarySurface>(mesh, a.feature_angle);
  const std::vector<std::uint8_t> fixed = surface ? surface->fixed_mask() : fixed_mask(mesh, a.fixed);
  std::size_t n_fixed = 0;
  for (std::uint8_t f : fixed) n_fixed += f != 0;
  fmt::print("{}: {} hexes, {} vertices, {} fixed\n", a.in, mesh.num_hexes(), mesh.num_vertices(), n_fixed);
  if (surface)
    fmt::print("boundary: {} vertices slide on the input's boundary, {} pinned on feature edges (> {} degrees)\n",
               surface->num_sliding(), surface->num_pinned(), a.feature_angle);
  if (a.fixed == FixedVertices::file && !mesh.has_fixed())
    fmt::print("note: {} carries no 'fixed' flags: every vertex may move\n", a.in);

  const MetricSummary before = sj_summary(mesh);
  print_quality("before", before);

  // Progress lines only on a terminal: logs and tests see the summaries alone.
  const bool tty = isatty(fileno(stderr)) != 0;
  ProgressCallback progress;
  if (tty)
    progress = [](const IterationReport& r) {
      fmt::print(stderr, "  {:<8} {:>4}  objective {:.6g}  min SJ {:.4f}  inverted {}\n", r.stage, r.iteration,
                 r.objective, r.min_sj, r.inverted);
    };

  nlohmann::json report;
  report["input"] = a.in;
  report["output"] = a.out;
  report["hexes"] = mesh.num_hexes();
  report["fixed_vertices"] = n_fixed;
  report["before"] = quality_json(before);

  if (a.untangle) {
    UntangleOptions uo;
    uo.margin = a.margin;
    uo.max_iter = std::max(a.max_iter, 1);
    uo.progress = progress;
    uo.surface = surface.get();
    const UntangleResult u = untangle(mesh, fixed, uo);
    nlohmann::json infeasible = nlohmann::json::array();
    for (const InfeasibleSet& f : u.infeasible)
      infeasible.push_back({{"kind", to_string(f.kind)}, {"vertex", f.vertex}, {"hexes", f.hexes}});
    report["untangle"] = {{"iterations", u.iterations}, {"min_sj", u.min_sj},         {"inverted", u.inverted},
                          {"reached_margin", u.reached_margin}, {"lp_moves", u.lp_moves}, {"infeasible", infeasible},
                          {"given_up", u.given_up}};
    if (!u.infeasible.empty()) {
      // The proofs first: they explain why the exit code will be 1 whatever else happens.
      fmt::print("untangle: {} sets of hexes cannot all be valid with these fixed vertices; {} hexes given up:\n",
                 u.infeasible.size(), u.given_up.size());
      for (std::size_t i = 0; i < u.infeasible.size() && i < 20; ++i) {
        const InfeasibleSet& f = u.infeasible[i];
        std::string ids;
        for (Index h : f.hexes) ids += fmt::format(" {}", h);
        if (f.kind == InfeasibleSet::Kind::fixed_frame)
          fmt::print("  fixed_frame: hex{} has an inverted frame made of fixed vertices only\n", ids);
        else
          fmt::print("  vertex_cone: free vertex {} has no place keeping all of hexes{} valid\n", f.vertex, ids);
      }
      if (u.infeasible.size() > 20) fmt::print("  ... ({} more in the JSON report)\n", u.infeasible.size() - 20);
    }
    fmt::print("untangle: {} iterations{}, min SJ {:.4f}{}, inverted {}{}\n", u.iterations,
               u.lp_moves ? fmt::format(" ({} LP moves)", u.lp_moves) : "", u.min_sj,
               u.given_up.empty() ? "" : " (hexes not given up)", u.inverted,
               u.reached_margin ? "" : fmt::format(" (margin {} not reached)", a.margin));
  } else if (before.inverted + before.degenerate > 0) {
    fmt::print("note: {} inverted hexes are held as they are (use --untangle to repair them)\n",
               before.inverted + before.degenerate);
  }

  ShapeOptions so;
  so.max_iter = a.max_iter;
  so.tol = a.tol;
  so.progress = progress;
  so.surface = surface.get();
  const ShapeResult s = optimize_shape(mesh, fixed, so);
  fmt::print("shape: {} sweeps, mean inverse mean ratio {:.6f} -> {:.6f}{}\n", s.iterations, s.objective_before,
             s.objective_after, s.frozen_hexes ? fmt::format(" ({} invalid hexes held)", s.frozen_hexes) : "");
  report["shape"] = {{"iterations", s.iterations}, {"objective_before", s.objective_before},
                     {"objective_after", s.objective_after}, {"frozen_hexes", s.frozen_hexes}};

  if (!a.no_worst) {
    WorstOptions wo;
    wo.progress = progress;
    wo.surface = surface.get();
    const WorstResult w = improve_worst(mesh, fixed, wo);
    fmt::print("worst: {} passes, {} moves, min SJ {:.4f} -> {:.4f}\n", w.passes, w.moves, w.min_sj_before,
               w.min_sj_after);
    report["worst"] = {{"passes", w.passes}, {"moves", w.moves}, {"min_sj_before", w.min_sj_before},
                       {"min_sj_after", w.min_sj_after}};
  }

  const MetricSummary after = sj_summary(mesh);
  print_quality("after", after);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  fmt::print("time: {:.2f} s\n", seconds);
  report["after"] = quality_json(after);
  if (surface) {
    // A self-check in the report: how far the sliding vertices are from the original surface.
    double far = 0;
    for (Index v = 0; v < mesh.num_vertices(); ++v)
      if (surface->role(v) == BoundarySurface::Role::slides)
        far = std::max(far, (surface->project(mesh.points[v]) - mesh.points[v]).norm());
    report["boundary"] = {{"mode", "slide"},       {"sliding", surface->num_sliding()},
                          {"pinned", surface->num_pinned()}, {"feature_angle", a.feature_angle},
                          {"max_distance", far}};
    fmt::print("boundary: sliding vertices at most {:.3g} from the input's boundary\n", far);
  }
  report["seconds"] = seconds;

  io::write_mesh(a.out, mesh);
  if (!a.json.empty()) write_json(a.json, report);
  // Scripts must notice a mesh that is still invalid (the mesh is written all the same: the
  // rest of it is untangled and the given-up hexes are listed above and in the JSON report).
  if (a.untangle && after.inverted + after.degenerate > 0) exit_code() = 1;
}

}  // namespace

void register_smooth(CLI::App& app) {
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "smooth", "Untangle and optimise element shape (inverse mean ratio), vertices on the boundary fixed by default");
  cmd->add_option("mesh", a->in, "Input hex mesh (.vtk .vtu .mesh .inp)")->required();
  cmd->add_option("-o,--output", a->out, "Output mesh")->required();
  cmd->add_flag("--untangle", a->untangle, "First make every hex valid (scaled Jacobian >= --margin where possible)");
  const std::map<std::string, FixedVertices> fixed_names{
      {"boundary", FixedVertices::boundary}, {"file", FixedVertices::file}, {"none", FixedVertices::none}};
  cmd->add_option("--fixed", a->fixed, "Fixed vertices: boundary (default), file (the mesh's 'fixed' flags), none")
      ->transform(CLI::CheckedTransformer(fixed_names, CLI::ignore_case));
  const std::map<std::string, bool> boundary_names{{"fixed", false}, {"slide", true}};
  cmd->add_option("--boundary", a->slide,
                  "Boundary vertices: fixed (default) or slide (move on the input's boundary surface, "
                  "feature-edge vertices pinned)")
      ->transform(CLI::CheckedTransformer(boundary_names, CLI::ignore_case));
  cmd->add_option("--feature-angle", a->feature_angle,
                  "With --boundary slide: boundary edges bent by more than this many degrees are features (default 30)")
      ->check(CLI::Range(0.0, 180.0));
  cmd->add_option("--max-iter", a->max_iter, "Iteration limit of each stage (default 100)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--tol", a->tol, "Stop the shape stage below this relative improvement per sweep (default 1e-5)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--margin", a->margin, "Untangling target for the minimum scaled Jacobian (default 0.05)");
  cmd->add_flag("--no-worst", a->no_worst, "Skip the worst-element pass");
  cmd->add_option("--json", a->json, "Write a JSON report (before/after quality, stage results)");
  cmd->add_flag("--skip-non-hex", a->skip_non_hex, "Drop non-hexahedral cells instead of failing");
  a->threads = add_threads_option(cmd);
  cmd->callback([a] { run(*a); });
}

}  // namespace isohex::cli
