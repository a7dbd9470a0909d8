#pragma once
// The stages `isohex mesh` runs after extraction and surface smoothing: boundary pillowing,
// untangling + shape optimisation with the boundary fixed or sliding, and the per-stage summary table.

#include "isohex/contour/dual_contour.hpp"
#include "isohex/contour/region.hpp"
#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/quality/summary.hpp"
#include "isohex/sheets/cut.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace isohex::cli {

/// One row of the summary table: the mesh as a stage left it.
struct StageRow {
  std::string name;
  Index hexes = 0, vertices = 0;
  std::vector<double> sj_values;  ///< per hex, for the report's histograms (empty without a report)
  MetricSummary sj;
  double seconds = 0;
  nlohmann::json extra = nlohmann::json::object();  ///< the stage's facts
};

/// Summarises `mesh` (scaled Jacobians computed here) as the row of stage `name`, keeping the
/// per-hex values only if `keep_values` (a report's histograms need them; without one, four
/// stages of cthead h 2 held 16 MiB of them to the end of the run).
StageRow stage_row(const std::string& name, const HexMesh& mesh, double seconds, bool keep_values);

/// Boundary pillowing: one sheet of hexes inside the whole boundary, the surface kept as it is.
/// `vertex_place` (one entry per vertex, see contour::ExtractResult) grows with the new
/// vertices, which are interior. Returns the JSON facts of the stage.
/// Pillows the boundary, the new vertices kept in `domain` (the sampled box).
nlohmann::json pillow_stage(HexMesh& mesh, std::vector<std::int8_t>& vertex_place, const Aabb& domain, bool terminal);

/// `isohex mesh --refine-boundary TOL`: contour::refine_boundary() on the extraction, its line
/// printed; returns its JSON facts and sets `seconds`.
nlohmann::json refine_stage(const contour::Region& region, contour::ExtractResult& extracted, double tolerance,
                            int levels, bool terminal, double& seconds);

/// A progress callback printing one line per iteration to `out` (flushed).
ProgressCallback progress_printer(std::FILE* out);

/// The optimisation sequence of `isohex smooth` and `isohex mesh` (optimize_mesh(): untangle,
/// shape, worst pass) with its printed lines (the untangler's proofs, first 20, and stop
/// reason; shape; worst). Returns the JSON facts ("untangle", "shape", "worst").
nlohmann::json run_optimisation(HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const OptimizeOptions& options);

// What a release round is judged by, worst first: hexes below 0.2 (certified scaled
// Jacobian), the smallest of those, hexes with a jacobian ratio below 0.1, the smallest ratio.
struct RoundScore {
  std::size_t below = 0, poor = 0;
  double min_sj = 2, min_ratio = 2;
  [[nodiscard]] bool worse_than(const RoundScore& o) const {
    if (below != o.below) return below > o.below;
    if (min_sj != o.min_sj) return min_sj < o.min_sj;
    if (poor != o.poor) return poor > o.poor;
    return min_ratio < o.min_ratio;
  }
};
/// The score of the whole mesh (the release rounds' and the cut attempts' judge).
RoundScore mesh_score(const HexMesh& mesh);
/// How a cut attempt ended, for the JSON reports of `isohex mesh --cut` and `isohex cut`:
/// {"below_0.2", "min_sj"}, with "tie_band" when `tie_band` > 0.
nlohmann::json attempt_json(const RoundScore& score, double tie_band = 0);

/// After a first run_optimisation() with `surface`: up to five rounds that release the
/// boundary vertices of the hexes still below 0.2 (or with a jacobian ratio below 0.1), and of
/// the hexes up to 3 vertex rings around them, into a band of half-width `band` (world
/// units) about their surface (BoundarySurface::loosen) and optimise again within 3 hex rings
/// of those hexes. Returns each round's JSON facts (with "released": vertices released).
/// Ends by putting released vertices back on their surface where the hexes allow it
/// (reattach_released()); how many, into `reattached` (may be null). Rounds that leave hexes
/// invalid run once more from their start in a band 5/3 as wide, and the better run is kept
/// (`band` then holds the wider band). `poor_left` (may be null): whether hexes are still below
/// 0.2 or have a jacobian ratio below 0.1 after the rounds (or before them, where none ran).
/// `widen_if_poor`: rounds that leave hexes below 0.2 (valid or not) run again wider too.
nlohmann::json release_rounds(HexMesh& mesh, BoundarySurface& surface, double& band, const OptimizeOptions& options,
                              std::size_t* reattached = nullptr, bool* poor_left = nullptr,
                              bool widen_if_poor = false);

/// What `isohex mesh --cut` leaves for the optimisation: the mesh it cut (its boundary quads
/// are the surface of vertices on no level set), the level sets (the region's surfaces, the
/// domain box's faces, the cuts) and what each vertex keeps to among them.
struct CutStage {
  HexMesh before;
  std::vector<contour::LevelSet> surfaces;
  std::vector<BoundarySurface::Constraint> constraints;
  int first_cut = 0;  ///< surfaces[first_cut + j] is cut j
};
/// The JSON facts of one cut (`isohex cut`, `isohex mesh --cut`, `--features sheets`);
/// `max_distance`: CutResult::max_distance of its surface.
nlohmann::json cut_step_json(const CutStep& step, double max_distance);

/// Cuts `mesh` (after pillowing) by `shapes`, then by `isosurfaces` (level sets of the volume's
/// other isovalues) (CutOptions: `keep`, the boundary on the region's
/// surfaces and the domain box's faces); `vertex_place` is rebuilt for the cut mesh (a boundary
/// vertex on a region surface or the box keeps that place; a vertex on a cut is interior to it).
nlohmann::json cut_stage(HexMesh& mesh, std::vector<std::int8_t>& vertex_place, const contour::Region& region,
                         const std::vector<Shape>& shapes, const std::vector<contour::LevelSet>& isosurfaces, CutKeep keep,
                         bool terminal, CutStage& stage, double tie_band = 0);

/// The tie band of the second cut (CutOptions::tie_band), tried when the first leaves hexes below
/// 0.2; the better of the two by RoundScore is kept.
inline constexpr double kRetryTieBand = 0.05;

/// One attempt's results, kept aside while the next runs.
struct CutAttempt {
  HexMesh mesh;
  std::vector<std::int8_t> place;
  CutStage cut;
  nlohmann::json cutting, optimisation;
  std::size_t inverted_left = 0;
  std::vector<std::uint8_t> released;
  std::vector<StageRow> rows;
};

/// Where the optimisation left each cut's vertices: the largest |L| / scale, printed and put in
/// `cutting["cuts"][j]["final_max_relative_distance"]`.
void report_cut_distances(const CutStage& stage, const HexMesh& mesh, nlohmann::json& cutting);

/// How `isohex mesh`'s optimisation treats the boundary: fixed (null region), or sliding
/// (`--boundary slide`): each boundary vertex on its own surface, the one `vertex_place` names
/// among region->surfaces. A vertex on one face of the domain box (an --outer box, or the
/// volume's box where it cuts the solid) slides in it; those on its edges and corners stay.
/// Vertices where two surfaces meet, or on creases sharper than `feature_degrees`, are pinned
/// (BoundarySurface).
struct SlideSpec {
  const contour::Region* region = nullptr;
  const std::vector<std::int8_t>* vertex_place = nullptr;
  double feature_degrees = 30;
  /// Band (world units) about their surface into which the sliding vertices of the hexes still
  /// below 0.2 after a first optimisation are released for a second one (`--surface-band`;
  /// 0: every sliding vertex stays on its surface).
  double band = 0;
  /// After cuts (`isohex mesh --cut`): the boundary is the cut's level sets and constraints; with
  /// `region` null (the boundary fixed) only the cut surfaces' vertices slide.
  const CutStage* cut = nullptr;
  const Aabb* domain = nullptr;  ///< the domain box, with `cut`
};

/// `isohex mesh`'s stage: run_optimisation() with the boundary fixed (or sliding, see SlideSpec)
/// and default options (the same as `isohex smooth --untangle`). Returns the JSON facts of the
/// stage; `inverted_left` is set to the hexes still inverted or degenerate at the end.
/// `released` (may be null) receives 1 for each vertex released into the band.
nlohmann::json optimise_stage(HexMesh& mesh, bool terminal, std::size_t& inverted_left, const SlideSpec& slide = {},
                              std::vector<std::uint8_t>* released = nullptr);

/// `isohex mesh --shape EXPR --features sheets`: meshes the shape by cuts (sheets/csg_cuts.hpp)
/// with hexes of `cell_size` (or `resolution` across), prints and writes it to `output`; one row
/// in `rows`; `inverted_left` = inverted + degenerate hexes. Returns the JSON report.
nlohmann::json mesh_shape_by_cuts(const std::string& expression, double cell_size, int resolution,
                                  const std::string& output, bool keep_values, std::vector<StageRow>& rows,
                                  std::size_t& inverted_left);

/// Prints the table of rows (hexes, vertices, min/mean SJ, #<0, #<0.2, time).
void print_stage_table(const std::vector<StageRow>& rows);
nlohmann::json stage_table_json(const std::vector<StageRow>& rows);

/// Writes the report folder (report.json, histograms, report.html with the 3D view of `mesh`).
void write_mesh_report(const std::string& dir, const std::string& title, const std::vector<StageRow>& rows,
                       const nlohmann::json& summary, const HexMesh& mesh);

/// Peak resident memory of this process so far, in MiB.
double peak_memory_mib();

}  // namespace isohex::cli
