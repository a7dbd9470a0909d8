// isohex cut IN -o OUT --surface EXPR... [--volume FILE --iso V...]: cut a hex mesh along
// implicit surfaces or isosurfaces by sheet insertion (§4.2), keeping both sides as blocks or
// one side.
#include "commands.hpp"
#include "mesh_stages.hpp"

#include "isohex/contour/iso_field.hpp"
#include "isohex/error.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/summary.hpp"
#include "isohex/sheets/cut.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <memory>

namespace isohex::cli {

namespace {

struct Args {
  std::string input, output, json, keep = "both", volume, inside = "above";
  std::vector<std::string> surfaces;
  std::vector<double> isos;
  VolumeReadArgs read;
  double offset = CutOptions{}.offset, feature_angle = CutOptions{}.feature_degrees, tie_band = 0;
  int rings = CutOptions{}.rings;
  bool no_optimize = false, skip_non_hex = false;
  int* threads = nullptr;
};

void run(const Args& a) {
  const auto t0 = std::chrono::steady_clock::now();
  ThreadLimit limit(*a.threads);
  std::vector<Shape> shapes;
  for (std::size_t i = 0; i < a.surfaces.size(); ++i) {
    try {
      shapes.push_back(parse_shape(a.surfaces[i]));
    } catch (const Error& e) {
      throw Error(fmt::format("cut: --surface {} ('{}'): {}", i + 1, a.surfaces[i], e.what()));
    }
  }
  if (a.surfaces.empty() && a.isos.empty()) throw Error("cut: give a cut surface: --surface EXPR or --volume FILE --iso V");
  if (a.volume.empty() != a.isos.empty())
    throw Error(a.volume.empty() ? "cut: --iso needs --volume FILE" : "cut: --volume needs --iso V (the isosurface to cut along)");
  if (!io::is_known_mesh_extension(a.output))
    throw Error(fmt::format("cut: {}: unknown mesh format (known: {})", a.output, io::kMeshExtensions));
  const VolumeReadOptions read = a.read.options();
  const HexMesh mesh = load_mesh(a.input, a.skip_non_hex);
  // The shapes first, then the isosurfaces, in the order given (the fields refer to `volume`,
  // which outlives them and the result).
  Volume volume;
  if (!a.volume.empty()) volume = read_volume(a.volume, read);
  std::vector<contour::LevelSet> surfaces;
  const double scale = cut_scale(mesh, CutOptions{});
  for (const Shape& s : shapes) surfaces.emplace_back(std::make_shared<const Shape>(s), scale);
  for (const double iso : a.isos)
    surfaces.emplace_back(std::make_shared<const IsoField>(volume, iso, *inside_from_name(a.inside)));
  CutOptions opt;
  opt.keep = *cut_keep_from_name(a.keep);
  opt.offset = a.offset;
  opt.feature_degrees = a.feature_angle;
  opt.rings = a.rings;
  opt.tie_band = a.tie_band;
  opt.optimize = !a.no_optimize;
  fmt::print("{}: {} hexes, {} vertices; {} cut(s), keep {}\n", a.input, mesh.num_hexes(), mesh.num_vertices(),
             surfaces.size(), a.keep);
  CutResult r = cut(mesh, surfaces, opt);
  nlohmann::json attempts;
  if (a.tie_band == 0 && opt.optimize) {
    // Hexes below 0.2: the cut again with a tie band (a surface through the middle of a layer of
    // hexes, docs/cutting.md), the better kept; a second cut that fails keeps the first.
    const RoundScore first = mesh_score(r.mesh);
    if (first.below > 0) {
      fmt::print("{} hexes below 0.2 (min SJ {:.4f}); the cut again with a tie band of {}\n", first.below, first.min_sj,
                 kRetryTieBand);
      opt.tie_band = kRetryTieBand;
      attempts = {{"first", attempt_json(first)}, {"kept", "first"}};
      try {
        CutResult again = cut(mesh, surfaces, opt);
        const RoundScore second = mesh_score(again.mesh);
        attempts["tie_band"] = attempt_json(second, kRetryTieBand);
        if (first.worse_than(second)) r = std::move(again), attempts["kept"] = "tie_band";
      } catch (const Error& e) {
        attempts["tie_band"] = {{"tie_band", kRetryTieBand}, {"error", e.what()}};
      }
      fmt::print("kept the {} cut\n", attempts["kept"].get<std::string>() == "first" ? "first" : "second");
    }
  }

  nlohmann::json report;
  report["input"] = a.input;
  report["output"] = a.output;
  report["keep"] = a.keep;
  report["tie_band"] = a.tie_band;
  if (!attempts.is_null()) report["attempts"] = attempts;
  nlohmann::json steps = nlohmann::json::array();
  for (std::size_t i = 0; i < r.steps.size(); ++i) {
    const CutStep& s = r.steps[i];
    fmt::print("cut {}: {}: {} hexes inside, {} outside ({} moved across); {} new sheet hexes{}; {} vertices on the "
               "surface ({} on curves, {} at corners){}\n",
               i + 1, s.surface, s.inside_hexes, s.outside_hexes, s.moved_across, s.sheet_hexes,
               s.dropped_hexes ? fmt::format(", {} dropped", s.dropped_hexes) : "", s.surface_vertices,
               s.curve_vertices, s.corner_vertices, s.unplaced ? fmt::format("; {} not placed", s.unplaced) : "");
    if (s.optimized)
      fmt::print("  optimised near the sheets: untangle {:.4f} ({} inverted), shape {} sweeps, worst {:.4f} -> {:.4f}\n",
                 s.optimisation.untangle.min_sj, s.optimisation.untangle.inverted, s.optimisation.shape.iterations,
                 s.optimisation.worst.min_sj_before, s.optimisation.worst.min_sj_after);
    steps.push_back(cut_step_json(s, r.max_distance[i]));
    steps.back()["surface_quads"] = r.surface_quads[i].size();
  }
  report["cuts"] = steps;
  std::vector<double> sj = scaled_jacobians(r.mesh);
  MeshJacobians jacobians = mesh_jacobians(r.mesh);
  const MetricSummary q = summarize(HexMetric::scaled_jacobian, sj, 5);
  const ValiditySummary validity = summarize_validity(jacobians);
  fmt::print("result: {} hexes, {} vertices\n", r.mesh.num_hexes(), r.mesh.num_vertices());
  fmt::print("scaled Jacobian: min {:.4f}  mean {:.4f}  inverted (< 0): {}  below {}: {}\n", q.min, q.mean, q.inverted,
             kQuestionableSJ, q.inverted + q.questionable + q.degenerate);
  fmt::print("{}\n", describe(validity));
  for (std::size_t i = 0; i < r.max_distance.size(); ++i)
    fmt::print("cut {}: {} quads on the surface, vertices within {:.3g} of it (relative to {})\n", i + 1,
               r.surface_quads[i].size(), r.max_distance[i],
               r.surfaces[r.surfaces.size() - r.steps.size() + i].field() ? "the volume's value range" : "the mesh's diagonal");
  report["quality"] = quality_json(q);
  report["validity"] = to_json(validity);
  report["hexes"] = r.mesh.num_hexes();
  report["vertices"] = r.mesh.num_vertices();
  report["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_result(a.output, r.mesh, io::quality_fields(std::move(sj), std::move(jacobians.ratio)));
  fmt::print("wrote {}\n", a.output);
  if (!a.json.empty()) write_json(a.json, report);
  if (q.inverted + q.degenerate > 0) exit_code() = 1;
}

}  // namespace

void register_cut(CLI::App& app) {
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("cut", "Cut a hex mesh along implicit surfaces by sheet insertion (sharp creases, "
                                            "Boolean-like cuts)");
  cmd->footer(
      "Examples:\n"
      "  isohex generate box -o cube.vtu -n 12 --size 2\n"
      "  isohex cut cube.vtu -o carved.vtu --surface \"sphere(1,1,1, 0.6)\" --keep outside\n"
      "  isohex cut cube.vtu -o two.vtu --surface \"plane(1,1,1, 1,0.3,0.2)\"   # two blocks, conforming\n"
      "  isohex cut cube.vtu -o c.vtu --surface \"sphere(1,1,1,0.6)\" --surface \"sphere(0,0,1,0.5)\" --keep outside\n"
      "  isohex generate box -o box.vtu -n 16 --size 40\n"
      "  isohex cut box.vtu -o lobes.vtu --volume hydrogen.vti --iso 0.1 --keep inside   # along an isosurface");
  cmd->add_option("input", a->input, "Hex mesh (.vtk .vtu .mesh .inp .msh .exo)")->required();
  cmd->add_option("-o,--output", a->output, "The cut mesh (a .vtu / .vtk / .exo carries per hex scaled_jacobian and jacobian_ratio)")->required();
  cmd->add_option("--surface", a->surfaces,
                  "A cut surface as a shape expression (see 'isohex volume shape --help'); its inside is the shape's. "
                  "Repeat for successive cuts");
  cmd->add_option("--volume", a->volume,
                  "Cut along isosurfaces of this volume (.nrrd .nhdr .mhd .mha .vtk .vti .nii .nii.gz, or .raw with "
                  "--dims --type), after the --surface cuts; it should cover the mesh");
  cmd->add_option("--iso", a->isos, "With --volume: an isovalue to cut along; repeat for successive cuts");
  cmd->add_option("--inside", a->inside, "With --volume: which side of the isovalue is the inside (default above)")
      ->check(CLI::IsMember({"above", "below"}));
  a->read.add_to(cmd);
  cmd->add_option("--keep", a->keep,
                  "both (default: the inside becomes a new block, the cut a conforming interface), inside or outside")
      ->check(CLI::IsMember({"both", "inside", "outside"}));
  cmd->add_option("--offset", a->offset, "Thickness of each new sheet / local edge length, in (0, 1) (default 0.25)");
  cmd->add_option("--feature-angle", a->feature_angle,
                  "Boundary edges bent by more than this many degrees are features of the input (default 30)")
      ->check(CLI::Range(0.0, 180.0));
  cmd->add_option("--rings", a->rings, "Optimise the vertices within this many hex rings of the new sheets (default 3)")
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--tie-band", a->tie_band,
                  "Hexes whose centre is within this fraction of their size of a surface count as outside it "
                  "(default 0: the sign alone, and when hexes end below 0.2 the cut again with 0.05, the better "
                  "kept; e.g. 0.05 where a surface runs through the middle of a layer of slightly moved hexes)")
      ->check(CLI::Range(0.0, 0.5));
  cmd->add_flag("--no-optimize", a->no_optimize, "Place the new sheets on the surfaces but do not optimise");
  cmd->add_option("--json", a->json, "Write a JSON report");
  cmd->add_flag("--skip-non-hex", a->skip_non_hex, "Drop non-hexahedral cells instead of failing");
  a->threads = add_threads_option(cmd);
  cmd->callback([a] { run(*a); });
}

}  // namespace isohex::cli
