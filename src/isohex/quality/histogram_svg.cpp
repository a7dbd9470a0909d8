// The quality-distribution figure: a bar chart like the paper's Figures 9, 11, 13 and 15.
#include "isohex/io/atomic_file.hpp"
#include "isohex/quality/plot_detail.hpp"
#include "isohex/quality/summary.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <ostream>

namespace isohex {

std::string histogram_svg(const MetricSummary& s, const HistogramPlotOptions& options) {
  const double W = 760, H = 440, left = 80, right = 20, top = 60, bottom = 70;
  const double pw = W - left - right, ph = H - top - bottom;
  const auto& h = s.histogram;
  const std::size_t n = h.counts.size();
  const detail::CountAxis axis(s, options.log_scale);
  const double decades = axis.decades;
  const std::vector<double>& ticks = axis.ticks;
  auto yfrac = [&](double count) { return axis.frac(count); };

  std::string svg;
  auto out = std::back_inserter(svg);
  fmt::format_to(out,
                 "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\" "
                 "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
                 W, H, W, H);
  const std::string title = options.title.empty() ? std::string(metric_name(s.metric)) + " distribution"
                                                  : options.title;
  fmt::format_to(out, "<text x=\"{}\" y=\"22\" font-size=\"16\" text-anchor=\"middle\">{}</text>\n", W / 2,
                 detail::escape_markup(title));
  std::string line = fmt::format("{} elements, min {:.4g}, mean {:.4g}, max {:.4g}", s.count, s.min, s.mean, s.max);
  if (s.metric == HexMetric::scaled_jacobian)
    line += fmt::format(", inverted {}, < {} {}", s.inverted, kQuestionableSJ, s.inverted + s.questionable);
  if (s.degenerate) line += fmt::format(", degenerate {}", s.degenerate);
  fmt::format_to(out, "<text x=\"{}\" y=\"42\" text-anchor=\"middle\" fill=\"#444\">{}</text>\n", W / 2, detail::escape_markup(line));

  // Axes and grid.
  if (options.log_scale) {
    for (int d = 0; d <= static_cast<int>(decades); ++d) {
      const double y = top + ph * (1 - yfrac(std::pow(10.0, d)));
      fmt::format_to(out, "<line x1=\"{}\" y1=\"{:.1f}\" x2=\"{}\" y2=\"{:.1f}\" stroke=\"#ddd\"/>\n", left, y, left + pw, y);
      fmt::format_to(out, "<text x=\"{}\" y=\"{:.1f}\" text-anchor=\"end\">{}</text>\n", left - 6, y + 4,
                     static_cast<long long>(std::pow(10.0, d)));
    }
  } else {
    for (double t : ticks) {
      const double y = top + ph * (1 - yfrac(t));
      fmt::format_to(out, "<line x1=\"{}\" y1=\"{:.1f}\" x2=\"{}\" y2=\"{:.1f}\" stroke=\"#ddd\"/>\n", left, y, left + pw, y);
      fmt::format_to(out, "<text x=\"{}\" y=\"{:.1f}\" text-anchor=\"end\">{}</text>\n", left - 6, y + 4, t);
    }
  }
  fmt::format_to(out, "<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"black\"/>\n", left, top, top + ph);
  fmt::format_to(out, "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"black\"/>\n", left, top + ph, left + pw);

  // Bars, with counts above them.
  const double bw = n ? pw / static_cast<double>(n) : pw;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = left + bw * static_cast<double>(i);
    const double bh = ph * yfrac(static_cast<double>(h.counts[i]));
    if (h.counts[i] > 0) {
      fmt::format_to(out,
                     "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"{}\" "
                     "stroke=\"white\"><title>[{:.3g}, {:.3g}): {}</title></rect>\n",
                     x, top + ph - bh, bw, bh, detail::bar_colour(s, h.edges[i]), h.edges[i], h.edges[i + 1], h.counts[i]);
      fmt::format_to(out, "<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\" font-size=\"10\">{}</text>\n",
                     x + bw / 2, top + ph - bh - 3, h.counts[i]);
    }
  }
  const std::size_t every = n > 10 ? 2 : 1;
  for (std::size_t i = 0; i <= n; i += every) {
    const double x = left + bw * static_cast<double>(i);
    fmt::format_to(out, "<text x=\"{:.1f}\" y=\"{}\" text-anchor=\"middle\">{:.3g}</text>\n", x, top + ph + 18,
                   h.edges[i]);
  }
  fmt::format_to(out, "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n", left + pw / 2, H - 22,
                 detail::escape_markup(metric_name(s.metric)));
  fmt::format_to(out,
                 "<text x=\"18\" y=\"{}\" text-anchor=\"middle\" transform=\"rotate(-90 18 {})\">elements{}</text>\n",
                 top + ph / 2, top + ph / 2, options.log_scale ? " (log scale)" : "");
  svg += "</svg>\n";
  return svg;
}

void write_histogram_svg(const std::filesystem::path& file, const MetricSummary& s,
                         const HistogramPlotOptions& options) {
  const std::string svg = histogram_svg(s, options);
  io::write_atomically(file, [&](std::ostream& os) { os << svg; });
}

}  // namespace isohex

namespace isohex::detail {

CountAxis::CountAxis(const MetricSummary& s, bool log) : log_scale(log) {
  const auto& c = s.histogram.counts;
  const std::size_t peak = c.empty() ? 0 : *std::max_element(c.begin(), c.end());
  decades = peak > 0 ? std::ceil(std::log10(static_cast<double>(peak))) : 0;
  ticks = linear_ticks(std::max<double>(static_cast<double>(peak), 1.0));
}

double CountAxis::frac(double count) const {
  if (log_scale) return count > 0 ? (1 + std::log10(count)) / (1 + decades) : 0.0;
  return count / std::max(ticks.back(), 1.0);
}

const char* bar_colour(const MetricSummary& s, double lo) {
  if (s.metric != HexMetric::scaled_jacobian) return "#4477aa";
  if (lo < 0) return "#cc3311";
  if (lo < kQuestionableSJ) return "#ee7733";
  return "#228833";
}

std::vector<double> linear_ticks(double top) {
  const double raw = top / 5;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  const double step = raw <= p ? p : raw <= 2 * p ? 2 * p : raw <= 5 * p ? 5 * p : 10 * p;
  std::vector<double> t;
  // Up to the first tick at or above `top`, so that the tallest bar stays inside the plot.
  for (double v = 0;; v += step) {
    t.push_back(v);
    if (v >= top) break;
  }
  return t;
}

std::string escape_markup(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace isohex::detail
