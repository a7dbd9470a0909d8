#pragma once
/// \file summary.hpp
/// \brief Distribution of a metric over a mesh: extremes, mean, the scaled-Jacobian classes
/// (inverted < 0, questionable < 0.2, degenerate), a histogram, and the worst elements.

#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"

#include <nlohmann/json_fwd.hpp>

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace isohex {

/// Threshold below which the paper (and isohex) calls an element questionable.
inline constexpr double kQuestionableSJ = 0.2;
/// Below this jacobian ratio (min det J / max det J) an element that is valid inside is counted
/// as poor (Gmsh's minJ/maxJ; solvers' elements lose accuracy long before it reaches 0).
inline constexpr double kPoorJacobianRatio = 0.1;

/// True if larger values of `m` mean better elements.
bool higher_is_better(HexMetric m);

/// Counts in consecutive bins [edges[i], edges[i+1]) (the last bin includes its right edge).
struct Histogram {
  std::vector<double> edges;
  std::vector<std::size_t> counts;
  std::size_t below = 0;  ///< values below edges.front()
  std::size_t above = 0;  ///< values above edges.back() (degenerate elements are not counted)
};

/// One element and its value.
struct ElementValue {
  Index id;
  double value;
};

/// The distribution of one metric over a mesh.
struct MetricSummary {
  HexMetric metric;
  std::size_t count = 0;        ///< elements
  std::size_t degenerate = 0;   ///< Verdict's 1e30 marker: never counted as good
  double min = 0, max = 0, mean = 0;  ///< over the non-degenerate elements
  std::size_t inverted = 0;     ///< scaled Jacobian < 0; jacobian_ratio <= 0 (not valid inside)
  std::size_t questionable = 0; ///< 0 <= scaled Jacobian < 0.2; 0 < jacobian_ratio < 0.1
  Histogram histogram;
  std::vector<ElementValue> worst;  ///< worst first; degenerate elements lead
};

/// Summarises `values` (one per hex) of metric `m`, keeping the `worst` worst elements.
/// The scaled Jacobian and the jacobian ratio use the paper's fixed bins (width 0.1 over
/// [-1, 1]); other metrics
/// 20 equal bins over [min, max]. Sequential sums keep the mean identical for any thread count.
MetricSummary summarize(HexMetric m, const std::vector<double>& values, std::size_t worst = 10);

/// Scaled Jacobian of a set of quads (e.g. the boundary of a hex mesh).
struct QuadSummary {
  std::size_t count = 0;
  double min = 0, mean = 0;        ///< 0 when there are no quads
  std::size_t below = 0;           ///< quads with scaled Jacobian < kQuestionableSJ
};

/// Summarises Verdict's quad scaled Jacobian over `quads` of `mesh` (parallel; the mean is
/// summed in quad order, so it does not depend on the thread count).
QuadSummary summarize_quads(const HexMesh& mesh, const std::vector<Quad>& quads);

/// JSON object of a summary (histogram and worst elements included).
nlohmann::json to_json(const MetricSummary& s);

/// Validity over the whole element (jacobian_bounds.hpp), counted over a mesh.
struct ValiditySummary {
  std::size_t hexes = 0;
  std::size_t not_valid_inside = 0;   ///< not certified valid inside (det J > 0 everywhere)
  std::size_t gauss_nonpositive = 0;  ///< det J <= 0 at one of the 2×2×2 Gauss points
  std::size_t poor = 0;               ///< valid inside, jacobian ratio below kPoorJacobianRatio
  double min_ratio = 1;               ///< the smallest jacobian ratio (1 for no hexes)
  std::vector<Index> invalid;         ///< the first `keep` hexes not valid inside (ascending)
};
/// Counts mesh_jacobians() of `mesh`, keeping up to `keep` ids of hexes not valid inside.
ValiditySummary summarize_validity(const HexMesh& mesh, std::size_t keep = 20);
/// The same from mesh_jacobians() already computed (whose ratios a writer may want too).
ValiditySummary summarize_validity(const MeshJacobians& jacobians, std::size_t keep = 20);
/// One line: "validity inside: N not valid inside, G with det J <= 0 at a Gauss point, ...".
std::string describe(const ValiditySummary& s);
nlohmann::json to_json(const ValiditySummary& s);

/// Options for the histogram figure.
struct HistogramPlotOptions {
  std::string title;         ///< e.g. the mesh name
  bool log_scale = false;    ///< logarithmic count axis
};

/// Writes the histogram as an SVG figure (bars coloured by class for the scaled Jacobian:
/// red inverted, orange questionable, green acceptable). Written atomically.
void write_histogram_svg(const std::filesystem::path& file, const MetricSummary& s,
                         const HistogramPlotOptions& options = {});
/// The SVG text itself.
std::string histogram_svg(const MetricSummary& s, const HistogramPlotOptions& options = {});

}  // namespace isohex
