#pragma once
/// \file report.hpp
/// \brief The quality report of a meshing run (`isohex mesh --report DIR`): report.json, the
/// scaled-Jacobian histogram of every stage as SVG and PNG, and a self-contained report.html
/// with the figures, the tables and an interactive WebGL cut-away view of the final mesh
/// coloured by scaled Jacobian. docs/report.md describes the files and the viewer.
///
/// Every file is written atomically (temporary file, then rename) and depends only on the
/// input: the same input gives the same bytes, so reports can be compared with `cmp`.

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/quality/png.hpp"
#include "isohex/quality/summary.hpp"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace isohex {

/// The mesh after one stage of the pipeline.
struct ReportStage {
  std::string name;               ///< e.g. "extraction", "surface smoothing", "pillowing", "optimization"
  std::vector<double> sj;         ///< scaled Jacobian of every hex after the stage (scaled_jacobians())
  std::size_t hexes = 0;          ///< 0: taken as sj.size()
  std::size_t vertices = 0;       ///< shown as given (0 is shown as "–")
  double seconds = -1;            ///< wall time of the stage; negative: not shown
  nlohmann::json extra = nlohmann::json::object();  ///< stage facts (iterations, moves, ...), shown as notes
};

/// Limits of the data embedded for the 3D viewer, so that report.html stays openable.
struct ReportViewerLimits {
  /// Meshes with at most this many hexes are embedded whole (every hex can be cut into).
  std::size_t max_hexes = 200000;
  /// Larger meshes embed their boundary quads and, inside, at most this many of the worst
  /// hexes (scaled Jacobian < 0.2 or degenerate, worst first); the page says so.
  std::size_t max_worst_hexes = 20000;
};

/// Everything the report shows.
struct ReportInput {
  std::string title = "isohex quality report";
  /// Whole-run facts (input, options, peak memory, distance to the isosurface, ...): an
  /// object, shown as a table (nested objects flattened to dotted keys) and copied to JSON.
  nlohmann::json summary = nlohmann::json::object();
  std::vector<ReportStage> stages;  ///< in pipeline order: the first is "before", the last "after"
  /// The final mesh for the 3D view (its hexes must match stages.back().sj); none: no view.
  const HexMesh* mesh = nullptr;
  bool log_scale = false;           ///< logarithmic count axis in the histograms
  ReportViewerLimits viewer;
};

/// The files write_report() wrote, relative to its folder.
struct ReportFiles {
  std::vector<std::string> files;
};

/// Creates `dir` (and its parents) if needed and writes into it: report.json,
/// histogram-<k>-<stage>.svg and .png for every stage k = 1, 2, ..., and report.html.
/// Throws isohex::Error if a file cannot be written or the input is inconsistent (a stage
/// without values, a mesh whose hex count differs from the last stage's).
ReportFiles write_report(const std::filesystem::path& dir, const ReportInput& in);

/// The histogram figure of `s` drawn as an image (the same chart as histogram_svg(), in a
/// 5×7 pixel font): bars coloured by class, count axis, bin edges, counts above the bars.
RgbImage histogram_image(const MetricSummary& s, const HistogramPlotOptions& options = {});
/// histogram_image() as PNG file bytes.
std::string histogram_png(const MetricSummary& s, const HistogramPlotOptions& options = {});

/// The per-hex data report.html embeds for its viewer (exposed for tests).
struct ViewerMesh {
  bool complete = true;            ///< every hex embedded (else: boundary + worst hexes)
  std::size_t mesh_hexes = 0;      ///< hexes in the mesh
  std::size_t worst_hexes = 0;     ///< interior worst hexes embedded when !complete
  std::vector<float> points;       ///< 3 per vertex, centred on the box and scaled to radius 1
  std::vector<std::uint32_t> quads;   ///< 4 vertex ids per quad, counter-clockwise seen from cell side[0]
  std::vector<std::int32_t> sides;    ///< 2 cell ids per quad (-1: nothing embedded on that side)
  std::vector<float> centroids;    ///< 3 per cell, same transform as points
  std::vector<float> sj;           ///< scaled Jacobian per cell (1e30 = degenerate)
  std::vector<std::int32_t> cell_hex;  ///< mesh hex id of each cell
};

/// Selects and packs the viewer data of `mesh` whose hexes have scaled Jacobians `sj`.
ViewerMesh viewer_mesh(const HexMesh& mesh, const std::vector<double>& sj, const ReportViewerLimits& limits);

}  // namespace isohex
