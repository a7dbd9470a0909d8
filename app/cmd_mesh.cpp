// isohex mesh VOLUME --iso V -o OUT: the hex mesh of a volume (or of a shape expression), from
// extraction to verification: dual contouring, surface smoothing, boundary pillowing,
// untangling + mean-ratio optimisation, then validation, the distance to the isosurface and a
// per-stage quality table.
#include "commands.hpp"
#include "mesh_stages.hpp"

#include "isohex/contour/dual_contour.hpp"
#include "isohex/contour/iso_field.hpp"
#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/validate.hpp"
#include "isohex/surface/smooth_region.hpp"
#include "isohex/quality/summary.hpp"
#include "isohex/volume/volume_io.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <ostream>
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace isohex::cli {

namespace {

// Gives the heap's free pages back to the system between stages (glibc): a stage's freed
// vectors otherwise stay resident as holes that the next stage's differently sized ones do
// not fill, and the peak RSS of cthead h 2 came at the final check, after the stages' peaks.
void release_free_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

struct Args {
  std::string volume, shape, output, json, report;
  std::optional<double> iso, iso2;
  std::string inside = "above", interpolation = "trilinear", region = "inside", outer;
  double cell_size = 0;
  Index resolution = 0, min_component = 8;
  double thin_features = 0.1;
  VolumeReadArgs read;  // the raw layout and memory limit, as in `isohex volume info`
  bool no_surface_smoothing = false, no_pillow = false, no_smooth = false;
  /// --boundary: slide (boundary vertices slide on their surfaces in the optimisation) or fixed;
  /// unset: slide unless --no-smooth.
  std::optional<bool> slide;
  int surface_iterations = 100;
  int surface_stall = 20;
  std::optional<double> refine_tolerance;  ///< --refine-boundary TOL
  int refine_levels = 1;
  std::optional<double> feature_angle;
  double surface_band = 0.3;  ///< --surface-band, in cell sizes
  std::string features = "round";  ///< --features
  std::vector<std::string> cuts;  ///< --cut EXPR...
  std::vector<double> cut_isos;   ///< --cut-iso V...
  std::string keep = "both";      ///< --keep
  int* threads = nullptr;
};

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The shape's signed distance sampled at half the mesh cell size, so that the trilinear
// interpolant follows the shape closely within each mesh cell.
Volume sample_shape(const Args& a, double& cell_size) {
  const Shape s = parse_shape(a.shape);
  const Aabb box = sampling_bounds(s);
  if (cell_size <= 0) cell_size = (box.hi - box.lo).maxCoeff() / (a.resolution > 0 ? a.resolution : 64);
  return sample(s, grid_from_cell_size(box, cell_size / 2));
}

// Smooths the boundary on each isosurface of the region in turn (smooth_region_surfaces).
std::vector<SurfaceSmoothingReport> smooth_surfaces(const contour::Region& region, contour::ExtractResult& out,
                                                    int iterations, int stall, double feature_angle, bool guard_hexes,
                                                    bool terminal) {
  SurfaceSmoothingOptions opt;
  opt.iterations = iterations;
  opt.stall_iterations = stall;
  opt.guard_hexes = guard_hexes;
  opt.field_crease_angle_degrees = feature_angle;
  if (!guard_hexes) opt.interior_layers = 0;  // the hexes below are re-shaped after pillowing
  return smooth_region_surfaces(region, out, opt, [&](std::size_t k) {
    if (terminal) fmt::print("  surface smoothing on {}...\n", region.surfaces[k].describe()), std::fflush(stdout);
  });
}

void print_smoothing(const contour::LevelSet& surface, const SurfaceSmoothingReport& s) {
  if (!surface.field()) return;
  fmt::print("surface smoothing on {}: {} iterations{}; boundary quad SJ min {:.4g} -> {:.4g}, mean {:.4g} -> {:.4g}, "
             "< {}: {} -> {}; fans < {}: {} -> {}; hexes inverted {} -> {}; max-min: {} passes, {} moves\n",
             surface.describe(), s.iterations, s.converged ? " (converged)" : s.stalled ? " (stalled)" : "", s.before.quad_sj_min,
             s.after.quad_sj_min, s.before.quad_sj_mean, s.after.quad_sj_mean, kQuestionableSJ, s.before.quads_below,
             s.after.quads_below, kQuestionableSJ, s.before.fans_below, s.after.fans_below, s.before.hexes_inverted,
             s.after.hexes_inverted, s.worst_passes, s.worst_moves);
}

nlohmann::json smoothing_json(const contour::LevelSet& surface, const SurfaceSmoothingReport& s) {
  auto q = [](const SurfaceQuality& x) {
    return nlohmann::json{{"boundary_quad_sj_min", x.quad_sj_min}, {"boundary_quad_sj_mean", x.quad_sj_mean},
                          {"boundary_quads_below_0.2", x.quads_below}, {"fan_margin_min", x.fan_margin_min},
                          {"fans_below_0.2", x.fans_below}, {"hex_sj_min", x.hex_sj_min},
                          {"hexes_inverted", x.hexes_inverted}};
  };
  return {{"surface", surface.describe()}, {"smoothed", surface.field() != nullptr}, {"iterations", s.iterations},
          {"converged", s.converged}, {"stalled", s.stalled}, {"before", q(s.before)}, {"after", q(s.after)},
          {"max_level_relative", s.max_level_relative}, {"max_displacement", s.max_displacement},
          {"max_min_passes", s.worst_passes}, {"max_min_moves", s.worst_moves}};
}

void print_summary(const MetricSummary& s) {
  fmt::print("  scaled Jacobian: min {:.4g}  mean {:.4g}  max {:.4g}\n", s.min, s.mean, s.max);
  fmt::print("  inverted (< 0): {}   questionable (< {}): {}   degenerate: {}\n", s.inverted, kQuestionableSJ,
             s.questionable, s.degenerate);
}

void run(const Args& a) {
  ThreadLimit limit(*a.threads);
  if (a.volume.empty() == a.shape.empty()) throw Error("give either a VOLUME file or --shape EXPR (not both)");
  if (!io::is_known_mesh_extension(a.output))
    throw Error(fmt::format("{}: unknown mesh format (use {})", a.output, io::kMeshExtensions));
  const bool terminal = ::isatty(::fileno(stdout)) != 0;
  const auto start = Clock::now();
  const bool cutting_asked = !a.cuts.empty() || !a.cut_isos.empty();
  if (!cutting_asked && a.keep != "both") throw Error("--keep is only used with --cut or --cut-iso");
  if (a.features == "sheets") {
    if (a.shape.empty()) throw Error("--features sheets meshes a --shape expression (a CSG solid), not a volume");
    if (cutting_asked) throw Error("--features sheets already cuts along the shape's surfaces; add them to --shape");
    std::vector<StageRow> rows;
    std::size_t inverted_left = 0;
    nlohmann::json j = mesh_shape_by_cuts(a.shape, a.cell_size, static_cast<int>(a.resolution), a.output,
                                          !a.report.empty(), rows, inverted_left);
    print_stage_table(rows);
    j["input"] = a.shape;
    j["stages"] = stage_table_json(rows);
    j["peak_memory_mib"] = peak_memory_mib();
    j["seconds"] = seconds_since(start);
    if (!a.json.empty()) write_json(a.json, j);
    if (!a.report.empty())
      write_mesh_report(a.report, fmt::format("isohex mesh --features sheets: {}", a.shape), rows, j, io::read_mesh(a.output));
    if (inverted_left > 0 || !j["valid"].get<bool>()) exit_code() = 1;
    return;
  }
  std::vector<Shape> cut_shapes;  // parsed before any work: a bad expression costs nothing
  for (std::size_t i = 0; i < a.cuts.size(); ++i) {
    try {
      cut_shapes.push_back(parse_shape(a.cuts[i]));
    } catch (const Error& e) {
      throw Error(fmt::format("--cut {} ('{}'): {}", i + 1, a.cuts[i], e.what()));
    }
  }

  contour::RegionSpec spec;
  spec.kind = *contour::region_from_name(a.region);
  spec.interpolation = *interpolation_from_name(a.interpolation);
  spec.inside = *inside_from_name(a.inside);
  double cell_size = a.cell_size;
  Volume volume;
  if (!a.shape.empty()) {
    volume = sample_shape(a, cell_size);
    spec.inside = Inside::below;  // signed distance: negative inside
    spec.isovalue = a.iso.value_or(0);
  } else {
    if (!a.iso) throw Error("--iso V is required with a volume file");
    volume = read_volume(a.volume, a.read.options());
    spec.isovalue = *a.iso;
  }
  std::vector<contour::LevelSet> cut_isos;  // the fields refer to `volume`, which outlives them
  for (const double iso : a.cut_isos) {
    if (iso == spec.isovalue || (a.iso2 && iso == *a.iso2))
      throw Error(fmt::format("--cut-iso {}: that is the region's own isosurface, not a surface inside it", iso));
    cut_isos.emplace_back(std::make_shared<const IsoField>(volume, iso, spec.inside, spec.interpolation));
  }
  const double read_time = seconds_since(start);
  if (spec.kind == contour::RegionKind::between) {
    if (!a.iso2) throw Error("--region between needs --iso2 V2");
    spec.isovalue2 = *a.iso2;
  } else if (a.iso2) {
    throw Error("--iso2 is only used with --region between");
  }
  if (!a.outer.empty()) {
    if (spec.kind != contour::RegionKind::outside) throw Error("--outer is only used with --region outside");
    spec.outer = contour::parse_outer(a.outer);
  }
  const contour::Region region = contour::make_region(volume, spec);
  // Every surface a region can have (isosurfaces, the outer sphere, an outer box's faces) is a
  // level set its vertices can slide on; only the optimisation stage slides them.
  const bool can_slide = !a.no_smooth;
  const bool slides = a.slide.value_or(can_slide);
  if (slides && !can_slide)
    throw Error("--boundary slide acts in the optimisation stage, which --no-smooth skips; use --boundary fixed or drop "
                "--no-smooth");

  contour::ExtractOptions opt;
  opt.cell_size = cell_size > 0 ? cell_size : 0;
  if (opt.cell_size <= 0) {
    if (a.resolution > 0) opt.resolution = a.resolution;
    else opt.cell_size = volume.spacing.maxCoeff();  // one voxel
  }
  opt.min_component = a.min_component;
  opt.thin_features = a.thin_features;
  if (terminal) opt.on_stage = [](std::string_view s) { fmt::print("  {}...\n", s), std::fflush(stdout); };

  fmt::print("{}: {} x {} x {} points, region {} ", a.shape.empty() ? a.volume : "shape", volume.dims[0],
             volume.dims[1], volume.dims[2], a.region);
  for (const auto& s : region.surfaces) fmt::print("[{}] ", s.describe());
  fmt::print("\n");
  contour::ExtractResult out = contour::extract_hex_mesh(region, opt);
  const contour::ExtractReport& r = out.report;
  fmt::print("grid {} x {} x {} points, cell size {:.6g}\n", r.grid.points[0], r.grid.points[1], r.grid.points[2],
             r.grid.h);

  std::vector<StageRow> rows;
  const bool keep_values = !a.report.empty();  // the report's histograms
  const double extraction_time = r.time_sample + r.time_repair + r.time_components + r.time_vertices + r.time_hexes;
  rows.push_back(stage_row("extraction", out.mesh, extraction_time, keep_values));
  nlohmann::json refinement;
  if (a.refine_tolerance) {
    double seconds = 0;
    refinement = refine_stage(region, out, *a.refine_tolerance, a.refine_levels, terminal, seconds);
    rows.push_back(stage_row("boundary refinement", out.mesh, seconds, keep_values));
  }
  auto t = Clock::now();
  // Scans have no sharp features: every crease of their quads is a fold.
  const double feature_angle = a.feature_angle.value_or(a.shape.empty() ? 180.0 : 30.0);
  const std::vector<SurfaceSmoothingReport> smoothing =
      a.no_surface_smoothing ? std::vector<SurfaceSmoothingReport>{} : smooth_surfaces(region, out, a.surface_iterations, a.surface_stall, feature_angle, a.no_pillow, terminal);
  const double smooth_time = seconds_since(t);
  for (std::size_t k = 0; k < smoothing.size(); ++k) print_smoothing(region.surfaces[k], smoothing[k]);
  if (!a.no_surface_smoothing) {
    rows.push_back(stage_row("surface smoothing", out.mesh, smooth_time, keep_values));
    for (std::size_t k = 0; k < smoothing.size(); ++k) {
      const SurfaceSmoothingReport& sr = smoothing[k];
      if (!region.surfaces[k].field()) continue;
      rows.back().extra[region.surfaces[k].describe()] =
          fmt::format("{} iterations; boundary quads < 0.2: {} -> {}, min quad SJ {:.3g} -> {:.3g}", sr.iterations,
                      sr.before.quads_below, sr.after.quads_below, sr.before.quad_sj_min, sr.after.quad_sj_min);
    }
  }

  release_free_memory();
  nlohmann::json pillowing, optimisation;
  if (!a.no_pillow) {
    t = Clock::now();
    pillowing = pillow_stage(out.mesh, out.vertex_place, region.domain, terminal);
    rows.push_back(stage_row("pillowing", out.mesh, seconds_since(t), keep_values));
    rows.back().extra = pillowing;
  }
  nlohmann::json cutting;
  CutStage cut;
  std::size_t inverted_left = 0;
  std::vector<std::uint8_t> released;  // vertices the optimisation released into the band
  const std::size_t rows_before = rows.size();
  const auto cut_and_optimise = [&](double tie_band) {
    if (cutting_asked) {
      t = Clock::now();
      cut = {};
      cutting = cut_stage(out.mesh, out.vertex_place, region, cut_shapes, cut_isos, *cut_keep_from_name(a.keep),
                          terminal, cut, tie_band);
      rows.push_back(stage_row("cut", out.mesh, seconds_since(t), keep_values));
    }
    release_free_memory();
    if (a.no_smooth) return;
    t = Clock::now();
    SlideSpec slide;
    if (slides)
      slide = {&region, &out.vertex_place, feature_angle, a.surface_band * r.grid.h};
    if (cutting_asked) slide.cut = &cut, slide.domain = &region.domain;
    optimisation = optimise_stage(out.mesh, terminal, inverted_left, slide, &released);
    rows.push_back(stage_row("optimisation", out.mesh, seconds_since(t), keep_values));
    rows.back().extra = {{"untangle", optimisation["untangle"]["iterations"]},
                         {"shape sweeps", optimisation["shape"]["iterations"]},
                         {"worst moves", optimisation["worst"]["moves"]}};
  };
  if (!cutting_asked || a.no_smooth) {
    cut_and_optimise(0);
  } else {
    // A cut whose surface runs through the middle of a layer of hexes classifies the layer by
    // the noise of the smoothing (CutOptions::tie_band): when the mesh ends with hexes below
    // 0.2, the cut and the optimisation run again from the pillowed mesh with a tie band, and
    // the better result is kept (cthead h 5, plane y = 110: 8 below 0.2 -> 0; at h 3, y = 90,
    // also mid-layer, the sign alone does better, hence not always).
    const HexMesh pillowed = out.mesh;
    const std::vector<std::int8_t> place = out.vertex_place;
    cut_and_optimise(0);
    const RoundScore first = mesh_score(out.mesh);
    if (first.below > 0) {
      fmt::print("cut: {} hexes below 0.2 after the optimisation (min SJ {:.4f}); again with the hexes within {} of "
                 "their size of the cut outside\n", first.below, first.min_sj, kRetryTieBand);
      // Swaps the first attempt's results out (and back if it stays the better).
      const auto exchange = [&](CutAttempt& k) {
        std::swap(out.mesh, k.mesh), std::swap(out.vertex_place, k.place), std::swap(cut, k.cut);
        std::swap(cutting, k.cutting), std::swap(optimisation, k.optimisation);
        std::swap(inverted_left, k.inverted_left), std::swap(released, k.released);
        std::vector<StageRow> tail(rows.begin() + static_cast<std::ptrdiff_t>(rows_before), rows.end());
        rows.resize(rows_before);
        rows.insert(rows.end(), k.rows.begin(), k.rows.end());
        k.rows = std::move(tail);
      };
      CutAttempt kept;
      exchange(kept);
      out.mesh = pillowed;
      out.vertex_place = place;
      cut_and_optimise(kRetryTieBand);
      const RoundScore second = mesh_score(out.mesh);
      const bool better = first.worse_than(second);
      fmt::print("cut: {} below 0.2 with the tie band (min SJ {:.4f}); the {} kept\n", second.below, second.min_sj,
                 better ? "second" : "first");
      nlohmann::json attempts = {{"first", attempt_json(first)},
                                 {"tie_band", attempt_json(second, kRetryTieBand)},
                                 {"kept", better ? "tie_band" : "first"}};
      if (!better) exchange(kept);
      cutting["attempts"] = std::move(attempts);
    }
  }

  if (cutting_asked) report_cut_distances(cut, out.mesh, cutting);
  release_free_memory();
  t = Clock::now();
  const ValidationReport check = validate(out.mesh);
  const contour::SurfaceDistance dist = contour::surface_distance(region, out.mesh, out.vertex_place, &released);
  const std::vector<double> sj = scaled_jacobians(out.mesh);
  const MetricSummary summary = summarize(HexMetric::scaled_jacobian, sj);
  MeshJacobians jacobians = mesh_jacobians(out.mesh);
  const ValiditySummary validity = summarize_validity(jacobians);
  // Vertices outside the sampled domain (a placement across it; 1e-9 of its diagonal spare).
  std::size_t outside_domain = 0;
  {
    const double slack = 1e-9 * (region.domain.hi - region.domain.lo).norm();
    for (const Vec3& x : out.mesh.points) outside_domain += !region.domain.contains(x, slack);
  }
  const double check_time = seconds_since(t);
  t = Clock::now();
  {
    // Per vertex, where the pipeline left it: "surface" the index of the region surface it lies
    // on (-1 inside, -2 on the domain box), "released" 1 if it was released into the band.
    // (`released` is empty where the optimisation did not run.)
    io::DataField surface{"surface", std::vector<double>(out.vertex_place.begin(), out.vertex_place.end())};
    io::DataField loose{"released", released.empty() ? std::vector<double>(out.mesh.points.size(), 0.0)
                                                     : std::vector<double>(released.begin(), released.end())};
    write_result(a.output, out.mesh, io::quality_fields(sj, std::move(jacobians.ratio)),
                 {std::move(surface), std::move(loose)});
  }
  const double write_time = seconds_since(t);

  fmt::print("mesh: {} hexes, {} vertices ({} on surfaces, {} on the domain box), {} boundary quads\n",
             out.mesh.num_hexes(), out.mesh.num_vertices(), dist.checked, dist.box_vertices, check.num_boundary_quads);
  fmt::print("  manifold repair: {} points made outside, {} made inside in {} rounds ({} simple and {} relocated, "
             "topology kept; {} forced; {} filling {} zero-volume cavities; {} simple at the isovalue; {} filling pinches "
             "of zero width); {} cells split\n",
             r.carved_points, r.filled_points, r.repair_rounds, r.simple_points, r.relocated_points, r.forced_points,
             r.degenerate_points, r.degenerate_components, r.zero_level_points, r.pinch_points, r.split_cells);
  if (r.thin_points > 0)
    fmt::print("  thin features: {} samples of filaments within {} cells of the isosurface made outside (of the {} above)\n",
               r.thin_points, a.thin_features, r.carved_points);
  if (a.min_component > 1)
    fmt::print("  components: {} kept, {} dropped ({} hexes) below {} hexes\n", r.components, r.dropped_components,
               r.dropped_hexes, a.min_component);
  fmt::print("  boundary: {} components, Euler characteristic {}, {}\n", check.num_boundary_components,
             check.euler_characteristic, check.valid() ? "valid conformal mesh, closed manifold" : "INVALID");
  for (const Fault& f : check.faults)
    if (is_error(f.kind)) fmt::print("    {}\n", f.message);
  fmt::print("  distance to the isosurface: max |f - iso| / range = {:.3g} over {} vertices ({} above 1e-6; {} box "
             "vertices not checked; {} projection fallbacks; {} placed again apart from a neighbour's)\n",
             dist.max_relative, dist.checked, dist.off_surface, dist.box_vertices, r.projection_fallbacks,
             r.separated_vertices);
  // The vertices released into the band (--surface-band), apart: their distance in world units.
  double released_far = 0, band = 0;
  const auto num_released = static_cast<std::size_t>(std::count(released.begin(), released.end(), 1));
  if (num_released > 0) {
    released_far = optimisation["boundary"]["max_loose_distance"].get<double>();
    band = optimisation["boundary"]["band"].get<double>();
    fmt::print("  released into the band: {} vertices ({} of them of the box's faces), up to {:.3g} from their surface "
               "({:.2f} cells; band {:.3g}); max |f - iso| / range {:.3g}\n",
               num_released, num_released - dist.released, released_far, released_far / r.grid.h, band,
               dist.released_max_relative);
  }
  if (region.surfaces.size() > 1 || dist.box_vertices > 0) {
    // Each surface against its own scale (value range, radius), and the box vertices, which may
    // slide in an outer box's faces, against the box.
    std::string each;
    for (std::size_t k = 0; k < region.surfaces.size(); ++k)
      each += fmt::format("{}{}: {:.3g} over {}", k ? "; " : "", region.surfaces[k].describe(),
                          dist.max_relative_per_surface[k], dist.checked_per_surface[k]);
    if (dist.box_vertices > 0)
      each += fmt::format("; domain box: {:.3g} (of its largest side) over {}", dist.box_max_relative, dist.box_vertices);
    fmt::print("  distance to each surface (max |L| / scale): {}\n", each);
  }
  print_summary(summary);
  fmt::print("  {}; {} vertices outside the domain\n", describe(validity), outside_domain);
  fmt::print("times: read {:.3f} s, sample {:.3f} s, repair {:.3f} s, components {:.3f} s, vertices {:.3f} s, hexes "
             "{:.3f} s, surface smoothing {:.3f} s, check {:.3f} s, write {:.3f} s\n",
             read_time, r.time_sample, r.time_repair, r.time_components, r.time_vertices, r.time_hexes, smooth_time,
             check_time, write_time);
  print_stage_table(rows);
  const double peak = peak_memory_mib();
  fmt::print("boundary distance to the isosurface: max |f - iso| / range {:.3g}{}; total {:.2f} s; peak memory {:.0f} MiB\n",
             dist.max_relative,
             num_released ? fmt::format(" ({} released vertices within {:.3g} = {:.2f} cells)", num_released, released_far,
                                         released_far / r.grid.h)
                           : "",
             seconds_since(start), peak);

  if (!a.json.empty() || !a.report.empty()) {
    nlohmann::json j;
    j["input"] = a.shape.empty() ? a.volume : a.shape;
    j["region"] = a.region;
    j["isovalue"] = spec.isovalue;
    if (a.iso2) j["isovalue2"] = *a.iso2;
    j["grid"] = {r.grid.points[0], r.grid.points[1], r.grid.points[2]};
    j["cell_size"] = r.grid.h;
    if (!cutting.is_null()) j["cutting"] = cutting;
    j["hexes"] = out.mesh.num_hexes();
    j["vertices"] = out.mesh.num_vertices();
    j["boundary_quads"] = check.num_boundary_quads;
    j["boundary_components"] = check.num_boundary_components;
    j["euler_characteristic"] = check.euler_characteristic;
    j["valid"] = check.valid();
    j["filled_points"] = r.filled_points;
    j["carved_points"] = r.carved_points;
    j["simple_points"] = r.simple_points;
    j["relocated_points"] = r.relocated_points;
    j["forced_points"] = r.forced_points;
    j["degenerate_components"] = r.degenerate_components;
    j["degenerate_points"] = r.degenerate_points;
    j["zero_level_points"] = r.zero_level_points;
    j["pinch_points"] = r.pinch_points;
    j["thin_points"] = r.thin_points;
    // Every sample the repair flipped, so that the topology claims can be checked.
    nlohmann::json edits = nlohmann::json::array();
    for (const auto& e : r.edits) {
      const Vec3 x = r.grid.origin + r.grid.h * Vec3(static_cast<double>(e.point[0]), static_cast<double>(e.point[1]),
                                                     static_cast<double>(e.point[2]));
      edits.push_back({{"grid", e.point}, {"position", {x[0], x[1], x[2]}}, {"inside", e.inside},
                       {"simple", e.kind == contour::RepairKind::simple},
                       {"kind", e.kind == contour::RepairKind::simple       ? "simple"
                                : e.kind == contour::RepairKind::relocated  ? "relocated"
                                : e.kind == contour::RepairKind::degenerate ? "degenerate"
                                : e.kind == contour::RepairKind::zero_level ? "zero_level"
                                : e.kind == contour::RepairKind::pinch      ? "pinch"
                                : e.kind == contour::RepairKind::thin       ? "thin"
                                                                            : "forced"}});
    }
    j["repair_edits"] = edits;
    j["split_cells"] = r.split_cells;
    j["dropped_components"] = r.dropped_components;
    j["dropped_hexes"] = r.dropped_hexes;
    j["surface_vertices"] = r.surface_vertices;
    j["box_vertices"] = r.box_vertices;
    j["projection_fallbacks"] = r.projection_fallbacks;
    j["separated_vertices"] = r.separated_vertices;
    j["max_relative_distance"] = dist.max_relative;
    j["off_surface_vertices"] = dist.off_surface;
    j["released_vertices"] = dist.released;
    j["released_max_relative_distance"] = dist.released_max_relative;
    j["released_max_distance"] = released_far;
    nlohmann::json per = nlohmann::json::array();
    for (std::size_t k = 0; k < region.surfaces.size(); ++k)
      per.push_back({{"surface", region.surfaces[k].describe()},
                     {"max_relative_distance", dist.max_relative_per_surface[k]},
                     {"vertices", dist.checked_per_surface[k]}});
    j["surface_distances"] = per;
    j["box_max_relative_distance"] = dist.box_max_relative;
    j["scaled_jacobian"] = to_json(summary);
    j["validity"] = to_json(validity);
    j["outside_domain_vertices"] = outside_domain;
    j["times"] = {{"read", read_time},          {"sample", r.time_sample}, {"repair", r.time_repair},
                  {"components", r.time_components}, {"vertices", r.time_vertices}, {"hexes", r.time_hexes},
                  {"surface_smoothing", smooth_time}, {"check", check_time}, {"write", write_time}};
    nlohmann::json sm = nlohmann::json::array();
    for (std::size_t k = 0; k < smoothing.size(); ++k) sm.push_back(smoothing_json(region.surfaces[k], smoothing[k]));
    j["surface_smoothing"] = sm;
    j["feature_angle_degrees"] = feature_angle;
    j["stages"] = stage_table_json(rows);
    if (a.refine_tolerance) j["refinement"] = refinement;
    if (!a.no_pillow) j["pillowing"] = pillowing;
    if (!a.no_smooth) j["optimisation"] = optimisation;
    j["peak_memory_mib"] = peak;
    j["seconds"] = seconds_since(start);
    if (!a.json.empty()) write_json(a.json, j);
    if (!a.report.empty()) {
      if (terminal) fmt::print("  writing the report...\n"), std::fflush(stdout);
      j.erase("repair_edits");  // in --json; too long for a page
      write_mesh_report(a.report, fmt::format("isohex mesh: {}", a.shape.empty() ? a.volume : a.shape), rows, j, out.mesh);
      fmt::print("report: {}/report.html\n", a.report);
    }
  }
  // A mesh a solver would refuse fails the run (it is written all the same, for inspection).
  // Without the optimisation (--no-smooth) the raw or pillowed mesh is asked for as it is (a
  // pillow without the surface smoothing may place inner copies outside the domain, headsq: 46).
  const bool unfit = !a.no_smooth && (validity.not_valid_inside > 0 || validity.gauss_nonpositive > 0 || outside_domain > 0);
  if (!check.valid() || dist.off_surface > 0 || released_far > band * (1 + 1e-3) || inverted_left > 0 || unfit)
    exit_code() = 1;
}

}  // namespace

void register_mesh(CLI::App& app) {
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("mesh", "Hex mesh of a volume's isosurface region: dual-contouring extraction, surface "
                                             "smoothing, boundary pillowing, untangling and mean-ratio optimisation, "
                                             "verification");
  cmd->footer(
      "Examples:\n"
      "  isohex mesh head.nrrd --iso 1150 --cell-size 3.2 -o head.vtu --json head.json\n"
      "  isohex mesh cthead.raw --dims 256 256 113 --type i16 --endian big --spacing 1 1 2 --iso 600 "
      "--cell-size 3 -o skin.inp\n"
      "  isohex mesh --shape \"torus(0,0,0, 1,0.4)\" --resolution 40 -o torus.vtu\n"
      "  isohex mesh cthead.raw --dims 256 256 113 --type i16 --endian big --spacing 1 1 2 --iso 600 --cell-size 4 "
      "--cut \"plane(0,110,0, 0,1,0)\" -o head.vtu   # the face cut off: two blocks\n"
      "  isohex mesh hydrogen.vti --iso 0.05 --cell-size 2 --cut-iso 0.2 --cut-iso 0.5 -o shells.vtu   # three "
      "nested blocks\n"
      "  isohex mesh --shape \"difference(box(0,0,0, 2,2,1), cylinder(1,1,-1, 1,1,2, 0.5))\" --features sheets "
      "--cell-size 0.1 -o plate.vtu");
  cmd->add_option("volume", a->volume, "Volume (.nrrd .nhdr .mhd .mha .vtk .vti .nii .nii.gz, or .raw with --dims --type)");
  cmd->add_option("--shape", a->shape, "Mesh an implicit shape expression instead (inside where its distance < ISO, default 0)");
  cmd->add_option("--iso", a->iso, "Isovalue");
  cmd->add_option("--inside", a->inside, "Which side of the isovalue is the solid (default above)")
      ->check(CLI::IsMember({"above", "below"}));
  cmd->add_option("--interpolation", a->interpolation, "Values between samples (default trilinear)")
      ->check(CLI::IsMember({"trilinear", "cubic", "smooth-cubic"}));
  auto* cs = cmd->add_option("--cell-size", a->cell_size, "Hex size in world units (default: one voxel, the largest spacing)")
                 ->check(CLI::PositiveNumber);
  cmd->add_option("--resolution", a->resolution, "Cells along the longest axis of the domain")
      ->check(CLI::PositiveNumber)
      ->excludes(cs);
  cmd->add_option("--region", a->region, "inside (default), outside (up to --outer), or between --iso and --iso2")
      ->check(CLI::IsMember({"inside", "outside", "between"}));
  cmd->add_option("--iso2", a->iso2, "Second isovalue of --region between");
  cmd->add_option("--outer", a->outer, "Outer boundary of --region outside: sphere:CX,CY,CZ,R or box:X0,Y0,Z0,X1,Y1,Z1 "
                                       "(default the volume's box)");
  cmd->add_option("--min-component", a->min_component,
                  "Drop connected parts with fewer hexes (default 8: a part smaller than a 2x2x2 block of cells is below "
                  "the cell size, mostly a scan's noise, and would float free in a solver; 0 keeps every part)");
  cmd->add_option("--thin-features", a->thin_features,
                  "Carve, from their tips, filaments one sample thick whose samples lie within F cells of the isosurface "
                  "(default 0.1: wisps far thinner than a cell, whose boundary quads fold round them and whose hexes "
                  "cannot reach a scaled Jacobian of 0.2; 0 keeps them)")
      ->check(CLI::Range(0.0, 0.5));
  cmd->add_option("--refine-boundary", a->refine_tolerance,
                  "Refine (by 3, conforming templates) the hexes under boundary quads that chord the isosurface "
                  "deeper than TOL x cell size, new boundary vertices on the isosurface (e.g. 0.02)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--refine-levels", a->refine_levels, "Rounds of --refine-boundary (default 1)")->check(CLI::Range(1, 3));
  cmd->add_flag("--no-surface-smoothing", a->no_surface_smoothing,
                "Skip the geometric-flow smoothing of the boundary quads (on by default; vertices stay on the isosurface)");
  cmd->add_option("--surface-iterations", a->surface_iterations,
                  "Most iterations of the surface smoothing (default 100; it stops earlier once no vertex moves more "
                  "than 1e-4 of the mean boundary edge, or once it stalls: --surface-stall)")
      ->check(CLI::Range(0, 10000));
  cmd->add_option("--surface-stall", a->surface_stall,
                  "Stop the surface smoothing's relaxation once this many iterations in a row bring the boundary quads "
                  "below 0.2 to no new low and raise their mean scaled Jacobian by less than 1e-4 in all (default 20; "
                  "0: run to --surface-iterations or convergence)")
      ->check(CLI::Range(0, 10000));
  cmd->add_option("--feature-angle", a->feature_angle,
                  "Surface smoothing keeps creases where the isosurface's normal turns by more than this (degrees; "
                  "default 30 for --shape, 180 = none for volumes: creases of a scan's quads are folds to unfold)")
      ->check(CLI::Range(0.0, 180.0));
  cmd->add_flag("--no-pillow", a->no_pillow,
                "Skip boundary pillowing (on by default: a sheet of hexes inside the boundary, surface unchanged)");
  cmd->add_flag("--no-smooth", a->no_smooth,
                "Skip untangling and mean-ratio optimisation (on by default; see --boundary)");
  const std::map<std::string, bool> boundary_names{{"fixed", false}, {"slide", true}};
  cmd->add_option("--boundary", a->slide,
                  "Boundary vertices in the optimisation: slide (the default: each moves on its own surface, an "
                  "isosurface, the --outer sphere or a face of the domain box (the volume's or the --outer box), and is "
                  "reprojected onto it; vertices on creases (--feature-angle), where two surfaces meet and on the box's "
                  "edges pinned) or fixed "
                  "(where they are after surface smoothing, the paper's setting)")
      ->transform(CLI::CheckedTransformer(boundary_names, CLI::ignore_case));
  cmd->add_option("--surface-band", a->surface_band,
                  "With --boundary slide: where hexes stay below 0.2 with their boundary on the surface (knife edges "
                  "thinner than a cell), release those boundary vertices into a band of this many cell sizes about "
                  "their surface and optimise again (default 0.3; 0: every vertex stays on its surface); rounds that "
                  "leave a hex invalid run again in a band 5/3 as wide, and the better run is kept")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--features", a->features,
                  "With --shape: round (default: the shape sampled and contoured, its edges rounded at the cell size) "
                  "or sheets (a grid of its bounding box cut along each smooth piece of its primitives: every crease "
                  "on a string of edges on the exact curve, every corner on its point)")
      ->check(CLI::IsMember({"round", "sheets"}));
  cmd->add_option("--cut", a->cuts,
                  "After pillowing, cut the mesh along this shape expression's surface by sheet insertion (see 'isohex "
                  "cut'): a string of edges on the crease where it meets the isosurface; repeat for successive cuts");
  cmd->add_option("--cut-iso", a->cut_isos,
                  "After pillowing (and the --cut shapes), cut the mesh along this isosurface of the same volume, its "
                  "inside on the --inside side (a material interface: two conforming blocks; the material must be several cells thick); repeat for "
                  "successive cuts");
  cmd->add_option("--keep", a->keep, "With --cut / --cut-iso: both (default: the inside a new block), inside or outside")
      ->check(CLI::IsMember({"both", "inside", "outside"}));
  cmd->add_option("-o,--output", a->output,
                  fmt::format("Output mesh ({}); a .vtu / .vtk / .exo carries per hex scaled_jacobian and jacobian_ratio, per "
                              "vertex surface (index, -1 inside, -2 domain box) and released (0/1)",
                              io::kMeshExtensions))
      ->required();
  cmd->add_option("--json", a->json, "Write the report as JSON");
  cmd->add_option("--report", a->report,
                  "Write a report folder: report.json, quality histograms per stage (SVG, PNG), report.html with a 3D "
                  "cut-away view coloured by scaled Jacobian");
  a->read.add_to(cmd);
  a->threads = add_threads_option(cmd);
  cmd->callback([a] { run(*a); });
}

}  // namespace isohex::cli
