// isohex quality MESH: the element-quality report (scaled Jacobian by default).
#include "commands.hpp"

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/quality/summary.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <ostream>

namespace isohex::cli {

namespace {

struct Args {
  std::string mesh;
  std::vector<std::string> metrics;
  std::string json, histogram, per_element;
  std::size_t worst = 10;
  bool log_scale = false, skip_non_hex = false;
  int* threads = nullptr;
};

std::vector<HexMetric> parse_metrics(const std::vector<std::string>& names) {
  std::vector<HexMetric> out;
  for (const std::string& n : names) {
    if (n == "all") {
      out.assign(kAllHexMetrics.begin(), kAllHexMetrics.end());
      continue;
    }
    auto m = metric_from_name(n);
    if (!m) {
      std::string known;
      for (HexMetric k : kAllHexMetrics) known += fmt::format(" {}", metric_name(k));
      throw Error(fmt::format("unknown metric '{}' (known:{} all)", n, known));
    }
    if (std::find(out.begin(), out.end(), *m) == out.end()) out.push_back(*m);
  }
  if (out.empty()) out.push_back(HexMetric::scaled_jacobian);
  return out;
}

// FILE.svg for one metric; FILE-<metric>.svg when several are plotted.
std::filesystem::path per_metric_path(const std::string& file, HexMetric m, std::size_t n) {
  std::filesystem::path p(file);
  if (n == 1) return p;
  return p.parent_path() / fmt::format("{}-{}{}", p.stem().string(), metric_name(m), p.extension().string());
}

void print_text_histogram(const Histogram& h) {
  const std::size_t peak = std::max<std::size_t>(1, *std::max_element(h.counts.begin(), h.counts.end()));
  for (std::size_t i = 0; i < h.counts.size(); ++i) {
    if (h.counts[i] == 0) continue;
    const auto bar = std::max<std::size_t>(1, h.counts[i] * 40 / peak);
    fmt::print("    [{:>7.3g}, {:>7.3g}) {:>9}  {}\n", h.edges[i], h.edges[i + 1], h.counts[i], std::string(bar, '#'));
  }
}

void print_summary(const MetricSummary& s) {
  fmt::print("{}: min {:.6g}  mean {:.6g}  max {:.6g}\n", metric_name(s.metric), s.min, s.mean, s.max);
  if (s.metric == HexMetric::scaled_jacobian)
    fmt::print("  inverted (< 0): {}   questionable (0 <= SJ < {}): {}   degenerate: {}\n", s.inverted,
               kQuestionableSJ, s.questionable, s.degenerate);
  else if (s.degenerate)
    fmt::print("  degenerate: {}\n", s.degenerate);
  print_text_histogram(s.histogram);
  if (!s.worst.empty()) {
    fmt::print("  worst:");
    for (const auto& e : s.worst) fmt::print(" {}={:.6g}", e.id, e.value);
    fmt::print("\n");
  }
}

void write_csv(const std::string& file, const std::vector<HexMetric>& metrics,
               const std::vector<std::vector<double>>& values) {
  io::write_atomically(file, [&](std::ostream& os) {
    std::string line = "id";
    if (metrics.size() == 1) line += ",value";
    else
      for (HexMetric m : metrics) line += fmt::format(",{}", metric_name(m));
    os << line << '\n';
    const std::size_t n = values.front().size();
    for (std::size_t i = 0; i < n; ++i) {
      line = fmt::format("{}", i);
      for (const auto& v : values) line += fmt::format(",{:.17g}", v[i]);
      line += '\n';
      os << line;
    }
  });
}

void run(const Args& a) {
  ThreadLimit limit(*a.threads);
  const std::vector<HexMetric> metrics = parse_metrics(a.metrics);
  const HexMesh mesh = load_mesh(a.mesh, a.skip_non_hex);
  const std::vector<QuadFace> quads = build_quads(mesh);
  const std::vector<Quad> boundary = boundary_quads(quads);
  fmt::print("{}: {} hexes, {} vertices, {} boundary quads\n", a.mesh, mesh.num_hexes(), mesh.num_vertices(),
             boundary.size());

  nlohmann::json report;
  report["mesh"] = a.mesh;
  report["hexes"] = mesh.num_hexes();
  report["vertices"] = mesh.num_vertices();
  report["boundary_quads"] = boundary.size();
  report["metrics"] = nlohmann::json::object();

  std::vector<std::vector<double>> all_values;
  for (HexMetric m : metrics) {
    std::vector<double> values = m == HexMetric::scaled_jacobian ? scaled_jacobians(mesh) : hex_metric(mesh, m);
    const MetricSummary s = summarize(m, values, a.worst);
    print_summary(s);
    report["metrics"][std::string(metric_name(m))] = to_json(s);
    if (!a.histogram.empty()) {
      HistogramPlotOptions opt;
      opt.title = fmt::format("{}: {}", std::filesystem::path(a.mesh).filename().string(), metric_name(m));
      opt.log_scale = a.log_scale;
      write_histogram_svg(per_metric_path(a.histogram, m, metrics.size()), s, opt);
    }
    all_values.push_back(std::move(values));
  }

  // Validity over the whole element, not at Verdict's nine samples: what a solver needs.
  const ValiditySummary validity = summarize_validity(mesh, a.worst);
  fmt::print("{}\n", describe(validity));
  report["validity"] = to_json(validity);

  // The surface's own quality: scaled Jacobian of the boundary quads.
  if (!boundary.empty()) {
    const QuadSummary bq = summarize_quads(mesh, boundary);
    fmt::print("boundary quad scaled_jacobian: min {:.6g}  mean {:.6g}  below {}: {}\n", bq.min, bq.mean,
               kQuestionableSJ, bq.below);
    report["boundary_quad_scaled_jacobian"] = {{"min", bq.min}, {"mean", bq.mean}, {"below_0.2", bq.below}};
  }

  if (!a.per_element.empty()) write_csv(a.per_element, metrics, all_values);
  if (!a.json.empty()) write_json(a.json, report);
}

}  // namespace

void register_quality(CLI::App& app) {
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("quality", "Element quality report (Verdict's scaled Jacobian and other metrics)");
  cmd->add_option("mesh", a->mesh, fmt::format("Hex mesh ({})", io::kMeshExtensions))->required();
  cmd->add_option("--metric", a->metrics,
                  "Metric to report, repeatable: scaled_jacobian (default), jacobian, edge_ratio, mean_ratio, shape, "
                  "skew, taper, volume, jacobian_ratio (certified min/max det J, Gmsh's minJ/maxJ), "
                  "gauss_jacobian (min det J at the 2x2x2 Gauss points), or all");
  cmd->add_option("--json", a->json, "Write the report as JSON");
  cmd->add_option("--histogram", a->histogram, "Write the quality-distribution figure (SVG; FILE-<metric>.svg per metric if several)");
  cmd->add_flag("--log-scale", a->log_scale, "Logarithmic count axis in the histogram figure");
  cmd->add_option("--per-element", a->per_element, "Write one 'id,value' line per hex (%.17g) to a CSV file");
  cmd->add_option("--worst", a->worst, "List the N worst elements (default 10)");
  cmd->add_flag("--skip-non-hex", a->skip_non_hex, "Drop non-hexahedral cells instead of failing");
  a->threads = add_threads_option(cmd);
  cmd->footer(
      "Every report ends with the validity inside the elements: det J certified > 0 everywhere (Bernstein bounds),\n"
      "det J at the 2x2x2 Gauss points, and the jacobian ratio.\n"
      "Example: isohex quality head.vtu --metric scaled_jacobian --metric jacobian_ratio --per-element head.csv");
  cmd->callback([a] { run(*a); });
}

}  // namespace isohex::cli
