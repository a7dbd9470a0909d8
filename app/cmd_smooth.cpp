// isohex smooth IN -o OUT: untangle, then optimise shape (inverse mean ratio), then raise the
// worst elements, with boundary / file-given / no vertices fixed.
#include "commands.hpp"
#include "mesh_stages.hpp"

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/summary.hpp"
#include "isohex/volume/hex_selection.hpp"
#include "isohex/volume/volume_io.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <unistd.h>

namespace isohex::cli {

namespace {

struct Args {
  std::string in, out, json;
  std::string volume, inside = "above";  ///< --boundary slide on the isosurface of a volume
  std::string fixed_ids;                 ///< --fixed-ids FILE: the fixed vertices, listed
  std::optional<double> iso;
  bool untangle = false, skip_non_hex = false, no_worst = false, slide = false;
  double feature_angle = 30;
  FixedVertices fixed = FixedVertices::boundary;
  std::optional<int> max_iter;  ///< unset: each stage's own limit (untangle 200, shape 100)
  double tol = ShapeOptions{}.tol, cull = ShapeOptions{}.cull, margin = 0.05;
  double surface_band = 0;  ///< --surface-band, in mean boundary edge lengths
  int patch_rounds = WorstOptions{}.patch_rounds;  ///< --patch-rounds
  int worst_passes = WorstOptions{}.passes;        ///< --worst-passes
  long long search_trials = static_cast<long long>(WorstOptions{}.search_trials);  ///< --search-trials
  std::optional<double> shape_guard;               ///< --shape-guard
  int* threads = nullptr;
};

MetricSummary sj_summary(const HexMesh& mesh) {
  return summarize(HexMetric::scaled_jacobian, scaled_jacobians(mesh), 5);
}

void print_quality(const char* label, const MetricSummary& s) {
  fmt::print("{:<7} scaled Jacobian: min {:.4f}  mean {:.4f}  inverted (< 0): {}  below {}: {}\n", label, s.min, s.mean,
             s.inverted, kQuestionableSJ, s.inverted + s.questionable + s.degenerate);
}

void run(const Args& a) {
  ThreadLimit limit(*a.threads);
  const auto t0 = std::chrono::steady_clock::now();
  if (a.slide && a.fixed != FixedVertices::boundary)
    throw Error("smooth: --boundary slide moves the boundary vertices; it needs --fixed boundary (the default)");
  if (!a.volume.empty() && !a.slide) throw Error("smooth: --volume is only used with --boundary slide");
  if (!a.volume.empty() && !a.iso) throw Error("smooth: --volume needs --iso V");
  if (a.volume.empty() && a.iso) throw Error("smooth: --iso is only used with --volume");
  if (!a.fixed_ids.empty() && (a.slide || a.fixed != FixedVertices::boundary))
    throw Error("smooth: --fixed-ids gives the fixed vertices itself; it cannot be combined with --boundary slide or --fixed");
  if (a.surface_band > 0 && !a.slide) throw Error("smooth: --surface-band releases sliding vertices; it needs --boundary slide");
  HexMesh mesh = load_mesh(a.in, a.skip_non_hex);
  // With --boundary slide the boundary vertices move on the input's own boundary surface, or
  // on the isosurface of --volume, except those on sharp feature edges (and, on an isosurface,
  // those off it): only those are fixed.
  std::unique_ptr<Volume> volume;
  std::unique_ptr<IsoField> field;
  std::unique_ptr<BoundarySurface> surface;
  if (!a.volume.empty()) {
    volume = std::make_unique<Volume>(read_volume(a.volume));
    field = std::make_unique<IsoField>(*volume, *a.iso, *inside_from_name(a.inside));
    surface = std::make_unique<BoundarySurface>(mesh, *field, a.feature_angle);
  } else if (a.slide) {
    surface = std::make_unique<BoundarySurface>(mesh, a.feature_angle);
  }
  const std::vector<std::uint8_t> fixed =
      surface              ? surface->fixed_mask()
      : a.fixed_ids.empty() ? fixed_mask(mesh, a.fixed)
                            : read_id_list(a.fixed_ids, mesh.points.size(), "vertex", "smooth --fixed-ids");
  std::size_t n_fixed = 0;
  for (std::uint8_t f : fixed) n_fixed += f != 0;
  fmt::print("{}: {} hexes, {} vertices, {} fixed\n", a.in, mesh.num_hexes(), mesh.num_vertices(), n_fixed);
  if (surface && field)
    fmt::print("boundary: {} vertices slide on the isosurface {} of {}, {} pinned (feature edges > {} degrees, or "
               "off the isosurface)\n",
               surface->num_sliding(), *a.iso, a.volume, surface->num_pinned(), a.feature_angle);
  else if (surface)
    fmt::print("boundary: {} vertices slide on the input's boundary, {} pinned on feature edges (> {} degrees)\n",
               surface->num_sliding(), surface->num_pinned(), a.feature_angle);
  if (a.fixed == FixedVertices::file && !mesh.has_fixed())
    fmt::print("note: {} carries no 'fixed' flags: every vertex may move\n", a.in);

  const MetricSummary before = sj_summary(mesh);
  print_quality("before", before);

  // Progress lines only on a terminal: logs and tests see the summaries alone.
  ProgressCallback progress;
  if (isatty(fileno(stderr)) != 0) progress = progress_printer(stderr);

  nlohmann::json report;
  report["input"] = a.in;
  report["output"] = a.out;
  report["hexes"] = mesh.num_hexes();
  report["fixed_vertices"] = n_fixed;
  report["before"] = quality_json(before);

  if (!a.untangle && before.inverted + before.degenerate > 0)
    fmt::print("note: {} inverted hexes are held as they are (use --untangle to repair them)\n",
               before.inverted + before.degenerate);
  // The same sequence as `isohex mesh` (mesh_stages.cpp: run_optimisation); only the options
  // given here differ from the defaults.
  OptimizeOptions o;
  o.untangle = a.untangle;
  o.worst = !a.no_worst;
  o.untangle_options.margin = a.margin;
  if (a.max_iter) {
    o.untangle_options.max_iter = std::max(*a.max_iter, 1);
    o.shape_options.max_iter = *a.max_iter;
  }
  o.shape_options.tol = a.tol;
  o.shape_options.cull = o.untangle_options.cull = a.cull;
  if (a.shape_guard) o.shape_options.rank_guard = *a.shape_guard;
  o.worst_options.patch_rounds = a.patch_rounds;
  o.worst_options.passes = a.worst_passes;
  o.worst_options.search_trials = static_cast<std::size_t>(a.search_trials);
  o.untangle_options.progress = o.shape_options.progress = o.worst_options.progress = progress;
  o.untangle_options.surface = o.shape_options.surface = o.worst_options.surface = surface.get();
  report.update(run_optimisation(mesh, fixed, o));
  double band = 0;
  if (surface && a.surface_band > 0) {
    // The band in the boundary's own unit: its mean edge length.
    double sum = 0;
    std::size_t edges = 0;
    for (const Quad& q : boundary_quads(mesh))
      for (int i = 0; i < 4; ++i, ++edges) sum += (mesh.points[q[(i + 1) % 4]] - mesh.points[q[i]]).norm();
    band = edges ? a.surface_band * sum / static_cast<double>(edges) : 0;
    std::size_t reattached = 0;
    report["rounds"] = release_rounds(mesh, *surface, band, o, &reattached);
    report["reattached"] = reattached;
  }

  const MetricSummary after = sj_summary(mesh);
  print_quality("after", after);
  const ValiditySummary validity = summarize_validity(mesh);
  fmt::print("        {}\n", describe(validity));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  fmt::print("time: {:.2f} s\n", seconds);
  report["after"] = quality_json(after);
  report["validity"] = to_json(validity);
  if (surface) {
    // A self-check in the report: how far the sliding vertices are from the target surface
    // (a distance for the input's boundary, |f - iso| / range for an isosurface).
    const auto [far, off] = surface->fit(mesh);
    report["boundary"] = {{"mode", "slide"},       {"sliding", surface->num_sliding()},
                          {"pinned", surface->num_pinned()}, {"feature_angle", a.feature_angle},
                          {"target", field ? "isosurface" : "input boundary"},
                          {"band", band},          {"loose", surface->num_loose()},
                          {"max_loose_distance", off}};
    if (surface->num_loose() > 0)
      fmt::print("boundary: {} vertices released within {:.3g} of their surface (band {:.3g})\n", surface->num_loose(),
                 off, band);
    if (field) {
      report["boundary"]["max_relative_level"] = far;
      fmt::print("boundary: sliding vertices at most {:.3g} x range from the isosurface (|f - iso| / range)\n", far);
    } else {
      report["boundary"]["max_distance"] = far;
      fmt::print("boundary: sliding vertices at most {:.3g} from the input's boundary\n", far);
    }
  }
  report["seconds"] = seconds;

  write_result(a.out, mesh);
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
  cmd->footer(
      "Examples:\n"
      "  isohex smooth tangled.vtk -o smooth.vtu --untangle --json smooth.json\n"
      "  isohex smooth pillowed.vtu -o out.vtu --untangle --boundary slide --surface-band 0.3 --patch-rounds 10\n"
      "  isohex smooth block.mesh -o out.vtu --untangle --worst-passes 100 --json r.json   # r.json: worst.proven\n"
      "  isohex smooth good.vtu -o better.vtu --shape-guard 0.3   # none falls below 0.3 by rank, none below it falls\n"
      "  isohex smooth stuck.vtu -o out.vtu --search-trials 1000000   # a longer random walk where hexes stay below 0.2");
  cmd->add_option("mesh", a->in, "Input hex mesh (.vtk .vtu .mesh .inp)")->required();
  cmd->add_option("-o,--output", a->out, "Output mesh (a .vtu / .vtk / .exo carries per hex scaled_jacobian and jacobian_ratio)")->required();
  cmd->add_flag("--untangle", a->untangle, "First make every hex valid (scaled Jacobian >= --margin where possible)");
  const std::map<std::string, FixedVertices> fixed_names{
      {"boundary", FixedVertices::boundary}, {"file", FixedVertices::file}, {"none", FixedVertices::none}};
  cmd->add_option("--fixed", a->fixed, "Fixed vertices: boundary (default), file (the mesh's 'fixed' flags), none")
      ->transform(CLI::CheckedTransformer(fixed_names, CLI::ignore_case));
  cmd->add_option("--fixed-ids", a->fixed_ids,
                  "Fixed vertices from a file instead: one vertex id per line ('#' comments); every other vertex moves");
  const std::map<std::string, bool> boundary_names{{"fixed", false}, {"slide", true}};
  cmd->add_option("--boundary", a->slide,
                  "Boundary vertices: fixed (default) or slide (move on the input's boundary surface, or on the "
                  "isosurface of --volume, feature-edge vertices pinned)")
      ->transform(CLI::CheckedTransformer(boundary_names, CLI::ignore_case));
  cmd->add_option("--volume", a->volume,
                  "With --boundary slide: slide on the isosurface --iso of this volume (.nrrd .nhdr .mhd .mha .vtk .vti "
                  ".nii .nii.gz) instead of the input's boundary; boundary vertices off it are pinned");
  cmd->add_option("--iso", a->iso, "With --volume: the isovalue");
  cmd->add_option("--inside", a->inside, "With --volume: which side of the isovalue is the solid (default above)")
      ->check(CLI::IsMember({"above", "below"}));
  cmd->add_option("--feature-angle", a->feature_angle,
                  "With --boundary slide: boundary edges bent by more than this many degrees are features (default 30)")
      ->check(CLI::Range(0.0, 180.0));
  cmd->add_option("--surface-band", a->surface_band,
                  "With --boundary slide: release the boundary vertices of hexes still below 0.2 into a band of this "
                  "many mean boundary edge lengths about their surface and optimise again (default 0: off); rounds that "
                  "leave a hex invalid run again in a band 5/3 as wide, and the better run is kept")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--max-iter", a->max_iter,
                  "Iteration limit of the untangler and the shape stage (default 200 and 100; the untangler "
                  "usually stops earlier, when it stalls)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--tol", a->tol, "Stop the shape stage below this relative improvement per sweep (default 5e-4)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--cull", a->cull,
                  "Untangling and shape stage: a sweep moves only the vertices near one that moved more than this "
                  "fraction of an edge in the sweep before (the untangler: also near hexes below the margin that are "
                  "not stuck; default 0.01; 0 moves every vertex every sweep)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--margin", a->margin, "Untangling target for the minimum scaled Jacobian (default 0.05)");
  cmd->add_flag("--no-worst", a->no_worst, "Skip the worst-element pass");
  cmd->add_option("--patch-rounds", a->patch_rounds,
                  "Rounds of joint moves that end the worst-element pass: the free vertices of each cluster of hexes "
                  "still below 0.2 move together, where single moves stall (default 5; 0: off)")
      ->check(CLI::Range(0, 100));
  cmd->add_option("--worst-passes", a->worst_passes,
                  "Passes of single-vertex max-min moves of the worst-element pass; it stops earlier when a pass "
                  "moves nothing (default 30)")
      ->check(CLI::Range(1, 10000));
  cmd->add_option("--search-trials", a->search_trials,
                  "Last of the worst-element pass, where at most 100 hexes are still below 0.2 (scaled Jacobian, or "
                  "twice the jacobian ratio): a random walk of the free vertices within two rings of each cluster of "
                  "them, each step taken when no hex around it falls below the cluster's minimum; at most this many "
                  "steps a cluster (default 200000; 0: off). Deterministic")
      ->check(CLI::Range(0LL, 100000000LL));
  cmd->add_option("--shape-guard", a->shape_guard,
                  "No shape step may take a hex's rank (the lower of its scaled Jacobian and twice its jacobian ratio) "
                  "below the lower of that rank before the step and this (default off; the band rounds after the "
                  "first use 0.2)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--json", a->json, "Write a JSON report (before/after quality, stage results)");
  cmd->add_flag("--skip-non-hex", a->skip_non_hex, "Drop non-hexahedral cells instead of failing");
  a->threads = add_threads_option(cmd);
  cmd->callback([a] { run(*a); });
}

}  // namespace isohex::cli
