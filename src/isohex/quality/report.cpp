// write_report(): report.json, the per-stage histogram figures and the self-contained
// report.html (tables, inline SVG figures, the embedded WebGL viewer).
#include "isohex/quality/plot_detail.hpp"
#include "isohex/quality/report.hpp"

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/quality/report_detail.hpp"

#include <fmt/format.h>

#include <cctype>
#include <optional>
#include <ostream>

namespace isohex {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {


// JSON for a <script> element: '<' escaped, so that no string can close the element.
std::string script_json(const json& j) {
  std::string s = j.dump();
  std::string out;
  for (char c : s) {
    if (c == '<') out += "\\u003c";
    else out += c;
  }
  return out;
}

// "surface smoothing" -> "surface-smoothing": a file-name part that any file system takes.
std::string slug(std::string_view name) {
  std::string s;
  for (char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isalnum(u)) s += static_cast<char>(std::tolower(u));
    else if (!s.empty() && s.back() != '-') s += '-';
  }
  while (!s.empty() && s.back() == '-') s.pop_back();
  return s.empty() ? "stage" : s;
}

std::string scalar_text(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) return fmt::format("{:.6g}", v.get<double>());
  return v.dump();
}

// Flattens nested objects to dotted keys; long arrays are summarised, not spelled out.
void flatten(const json& j, const std::string& prefix, std::vector<std::pair<std::string, std::string>>& rows) {
  if (j.is_null() && prefix.empty()) return;  // no facts given
  if (j.is_object()) {
    for (const auto& [k, v] : j.items()) flatten(v, prefix.empty() ? k : prefix + "." + k, rows);
    return;
  }
  if (j.is_array()) {
    bool scalars = j.size() <= 8;
    for (const auto& v : j) scalars = scalars && v.is_primitive();
    if (scalars) {
      std::string s;
      for (const auto& v : j) s += (s.empty() ? "" : ", ") + scalar_text(v);
      rows.emplace_back(prefix, "[" + s + "]");
    } else {
      rows.emplace_back(prefix, fmt::format("[{} entries, in report.json]", j.size()));
    }
    return;
  }
  rows.emplace_back(prefix, scalar_text(j));
}

std::string sj_text(double v) { return fmt::format("{:.4g}", v); }

void write_text(const fs::path& file, const std::string& text) {
  io::write_atomically(file, [&](std::ostream& os) { os.write(text.data(), static_cast<std::streamsize>(text.size())); });
}

struct StageResult {
  const ReportStage* stage;
  MetricSummary summary;
  std::string svg, svg_file, png_file;
};

std::string cards_html(const std::vector<StageResult>& r) {
  const MetricSummary& last = r.back().summary;
  double total = 0;
  bool timed = false;
  for (const auto& s : r)
    if (s.stage->seconds >= 0) total += s.stage->seconds, timed = true;
  std::string h = "<div class=\"cards\">\n";
  auto card = [&](const std::string& value, const std::string& label, bool bad) {
    h += fmt::format("<div class=\"card\"><b{}>{}</b><span>{}</span></div>\n", bad ? " class=\"bad\"" : "", value, label);
  };
  card(fmt::format("{}", last.count), "hexes", false);
  card(sj_text(last.min), "min scaled Jacobian", last.min < 0);
  card(sj_text(last.mean), "mean scaled Jacobian", false);
  card(fmt::format("{}", last.inverted), "inverted (SJ &lt; 0)", last.inverted > 0);
  card(fmt::format("{}", last.inverted + last.questionable), fmt::format("SJ &lt; {}", kQuestionableSJ), false);
  if (last.degenerate) card(fmt::format("{}", last.degenerate), "degenerate", true);
  if (timed) card(fmt::format("{:.2f} s", total), "time of the stages", false);
  return h + "</div>\n";
}

std::string stage_table_html(const std::vector<StageResult>& r) {
  std::string h =
      "<table>\n<tr><th class=\"l\">stage</th><th>hexes</th><th>vertices</th><th>min SJ</th><th>mean SJ</th>"
      "<th>SJ &lt; 0</th><th>SJ &lt; 0.2</th><th>degenerate</th><th>time (s)</th><th class=\"l\">notes</th></tr>\n";
  for (const auto& s : r) {
    const MetricSummary& m = s.summary;
    std::vector<std::pair<std::string, std::string>> notes;
    flatten(s.stage->extra, "", notes);
    std::string n;
    for (const auto& [k, v] : notes) n += (n.empty() ? "" : "; ") + detail::escape_markup(k) + ": " + detail::escape_markup(v);
    h += fmt::format(
        "<tr><td class=\"l\">{}</td><td>{}</td><td>{}</td><td{}>{}</td><td>{}</td><td{}>{}</td><td>{}</td><td>{}</td>"
        "<td>{}</td><td class=\"l\">{}</td></tr>\n",
        detail::escape_markup(s.stage->name), m.count, s.stage->vertices ? fmt::format("{}", s.stage->vertices) : "–",
        m.min < 0 ? " class=\"bad\"" : "", sj_text(m.min), sj_text(m.mean), m.inverted ? " class=\"bad\"" : "",
        m.inverted, m.inverted + m.questionable, m.degenerate,
        s.stage->seconds >= 0 ? fmt::format("{:.3f}", s.stage->seconds) : "–", n);
  }
  return h + "</table>\n";
}

std::string facts_table_html(const json& summary) {
  std::vector<std::pair<std::string, std::string>> rows;
  flatten(summary, "", rows);
  if (rows.empty()) return "<p class=\"note\">No run facts were given.</p>\n";
  std::string h = "<table>\n";
  for (const auto& [k, v] : rows)
    h += fmt::format("<tr><th class=\"l\">{}</th><td class=\"l\">{}</td></tr>\n", detail::escape_markup(k), detail::escape_markup(v));
  return h + "</table>\n";
}

std::string viewer_note(const ViewerMesh& v) {
  if (v.complete)
    return fmt::format("All {} hexes are embedded: every hex can be cut into.", v.mesh_hexes);
  return fmt::format(
      "The mesh has {} hexes, more than this page embeds: it shows the boundary of the mesh (a shell, open where it "
      "is cut) and, inside it, the {} worst hexes (scaled Jacobian &lt; {} or degenerate, worst first).",
      v.mesh_hexes, v.worst_hexes, kQuestionableSJ);
}

}  // namespace

ReportFiles write_report(const fs::path& dir, const ReportInput& in) {
  if (in.stages.empty()) throw Error("report: no stages to report");
  for (const auto& s : in.stages)
    if (s.sj.empty() && s.hexes != 0) throw Error(fmt::format("report: stage \"{}\" has no scaled Jacobians", s.name));
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) throw Error(fmt::format("{}: cannot create the report folder: {}", dir.string(), ec.message()));

  ReportFiles files;
  std::vector<StageResult> results;
  json stages = json::array();
  for (std::size_t k = 0; k < in.stages.size(); ++k) {
    const ReportStage& st = in.stages[k];
    StageResult r{&st, summarize(HexMetric::scaled_jacobian, st.sj), {}, {}, {}};
    HistogramPlotOptions plot;
    plot.title = fmt::format("{}. {}: scaled Jacobian", k + 1, st.name);
    plot.log_scale = in.log_scale;
    const std::string base = fmt::format("histogram-{}-{}", k + 1, slug(st.name));
    r.svg = histogram_svg(r.summary, plot);
    r.svg_file = base + ".svg";
    r.png_file = base + ".png";
    write_text(dir / r.svg_file, r.svg);
    write_text(dir / r.png_file, histogram_png(r.summary, plot));
    files.files.push_back(r.svg_file);
    files.files.push_back(r.png_file);

    json js{{"name", st.name},        {"hexes", st.hexes ? st.hexes : st.sj.size()},
            {"vertices", st.vertices}, {"scaled_jacobian", to_json(r.summary)},
            {"extra", st.extra},       {"figures", {{"svg", r.svg_file}, {"png", r.png_file}}}};
    if (st.seconds >= 0) js["seconds"] = st.seconds;
    stages.push_back(std::move(js));
    results.push_back(std::move(r));
  }

  std::optional<ViewerMesh> view;
  if (in.mesh) view = viewer_mesh(*in.mesh, in.stages.back().sj, in.viewer);

  json report{{"format", "isohex-report"}, {"version", 1}, {"title", in.title}, {"summary", in.summary},
              {"stages", stages}};
  if (view) report["viewer"] = report_detail::viewer_info(*view);
  files.files.push_back("report.json");
  files.files.push_back("report.html");
  report["files"] = files.files;
  write_text(dir / "report.json", report.dump(2) + "\n");

  // The page: every part inline (style, figures, script, data), nothing fetched.
  std::string h;
  h += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
       "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  h += fmt::format("<title>{}</title>\n<style>{}</style>\n</head>\n<body>\n", detail::escape_markup(in.title),
                   report_detail::kReportCss);
  h += fmt::format("<h1>{}</h1>\n", detail::escape_markup(in.title));
  h += cards_html(results);
  if (view) {
    h += report_detail::kViewerHtml;
  } else {
    h += "<p class=\"note\">No mesh was given for a 3D view.</p>\n";
  }
  h += "<h2>Stages</h2>\n" + stage_table_html(results);
  h += "<h2>Quality distribution</h2>\n<div class=\"figures\">\n";
  for (const auto& r : results)
    h += fmt::format("<figure>\n{}<figcaption>{} (<a href=\"{}\">SVG</a>, <a href=\"{}\">PNG</a>)</figcaption>\n</figure>\n",
                     r.svg, detail::escape_markup(r.stage->name), r.svg_file, r.png_file);
  h += "</div>\n<h2>Run</h2>\n" + facts_table_html(in.summary);
  h += "<p class=\"note\">Written by isohex. The numbers are also in report.json; scaled Jacobians follow Verdict "
       "(1 for a cube, below 0 for an inverted hex).</p>\n";
  if (view) {
    h += fmt::format("<script>document.getElementById('viewer-note').innerHTML = {};</script>\n",
                     script_json(viewer_note(*view)));
    h += fmt::format("<script type=\"application/json\" id=\"mesh-info\">{}</script>\n",
                     script_json(report_detail::viewer_info(*view)));
    h += "<script type=\"application/octet-stream\" id=\"mesh-data\">\n" + report_detail::viewer_payload(*view) +
         "\n</script>\n";
    h += std::string("<script>") + report_detail::kViewerJs + "</script>\n";
  }
  h += "</body>\n</html>\n";
  write_text(dir / "report.html", h);
  return files;
}

}  // namespace isohex
