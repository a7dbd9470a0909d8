// The quality-distribution figure as a raster image: the chart of histogram_svg.cpp drawn
// with RgbImage, for viewers and documents that take PNG but not SVG.
#include "isohex/quality/plot_detail.hpp"
#include "isohex/quality/report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace isohex {

namespace {

void centred_text(RgbImage& img, int cx, int y, const std::string& s, Rgb c, int scale) {
  img.text(cx - RgbImage::text_width(s, scale) / 2, y, s, c, scale);
}

}  // namespace

RgbImage histogram_image(const MetricSummary& s, const HistogramPlotOptions& options) {
  // Twice the font size of a screen label: the figure is meant to be read when scaled down.
  const int W = 900, H = 530, left = 100, right = 24, top = 96, bottom = 78;
  const int pw = W - left - right, ph = H - top - bottom;
  const Rgb ink{34, 34, 34}, grey{90, 90, 90}, grid{221, 221, 221};
  RgbImage img(W, H);

  const auto& h = s.histogram;
  const std::size_t n = h.counts.size();
  const detail::CountAxis axis(s, options.log_scale);  // as in the SVG figure
  const double decades = axis.decades;
  const std::vector<double>& ticks = axis.ticks;
  auto yfrac = [&](double count) { return axis.frac(count); };
  auto ypix = [&](double count) { return top + static_cast<int>(std::lround(ph * (1 - yfrac(count)))); };

  const std::string title = options.title.empty() ? std::string(metric_name(s.metric)) + " distribution" : options.title;
  const int title_scale = RgbImage::text_width(title, 3) <= W - 20 ? 3 : RgbImage::text_width(title, 2) <= W - 20 ? 2 : 1;
  centred_text(img, W / 2, 12, title, ink, title_scale);
  // The facts under the title, on two lines when one does not fit at the label size.
  std::vector<std::string> lines{fmt::format("{} elements, min {:.4g}, mean {:.4g}, max {:.4g}", s.count, s.min, s.mean, s.max)};
  std::string classes;
  if (s.metric == HexMetric::scaled_jacobian)
    classes = fmt::format("inverted {}, < {} {}", s.inverted, kQuestionableSJ, s.inverted + s.questionable);
  if (s.degenerate) classes += fmt::format("{}degenerate {}", classes.empty() ? "" : ", ", s.degenerate);
  if (!classes.empty()) {
    if (RgbImage::text_width(lines[0] + ", " + classes, 2) <= W - 20) lines[0] += ", " + classes;
    else lines.push_back(classes);
  }
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const int scale = RgbImage::text_width(lines[i], 2) <= W - 20 ? 2 : 1;
    centred_text(img, W / 2, 42 + 18 * static_cast<int>(i), lines[i], grey, scale);
  }

  // Grid lines and count labels.
  std::vector<std::pair<double, std::string>> yt;
  if (options.log_scale) {
    for (int d = 0; d <= static_cast<int>(decades); ++d) {
      const double v = std::pow(10.0, d);
      yt.emplace_back(v, fmt::format("{}", static_cast<long long>(v)));
    }
  } else {
    for (double t : ticks) yt.emplace_back(t, fmt::format("{}", t));
  }
  for (const auto& [v, label] : yt) {
    const int y = ypix(v);
    img.hline(left, left + pw, y, grid);
    img.text(left - 8 - RgbImage::text_width(label, 2), y - 7, label, ink, 2);
  }

  // Bars (a white gap between neighbours, as the SVG's white stroke), counts above them.
  const double bw = n ? static_cast<double>(pw) / static_cast<double>(n) : pw;
  for (std::size_t i = 0; i < n; ++i) {
    if (h.counts[i] == 0) continue;
    const int x0 = left + static_cast<int>(std::lround(bw * static_cast<double>(i))) + 1;
    const int x1 = left + static_cast<int>(std::lround(bw * static_cast<double>(i + 1)));
    // At least one pixel high, so that a single inverted hex is visible next to thousands.
    const int y0 = std::min(ypix(static_cast<double>(h.counts[i])), top + ph - 1);
    img.fill_rect(x0, y0, x1, top + ph, rgb_from_hex(detail::bar_colour(s, h.edges[i])));
    const std::string c = fmt::format("{}", h.counts[i]);
    const int scale = RgbImage::text_width(c, 2) <= x1 - x0 ? 2 : 1;
    centred_text(img, (x0 + x1) / 2, y0 - 4 - 7 * scale, c, ink, scale);
  }
  img.vline(left, top, top + ph, ink);
  img.hline(left, left + pw, top + ph, ink);

  // Bin edges under the axis (every other one when there are many bins, as in the SVG).
  const std::size_t every = n > 10 ? 2 : 1;
  for (std::size_t i = 0; i <= n && i < h.edges.size(); i += every) {
    const int x = left + static_cast<int>(std::lround(bw * static_cast<double>(i)));
    img.vline(x, top + ph, top + ph + 4, ink);
    centred_text(img, x, top + ph + 10, fmt::format("{:.3g}", h.edges[i]), ink, 2);
  }
  const std::string xlabel(metric_name(s.metric));
  centred_text(img, left + pw / 2, H - 34, xlabel, ink, 2);
  const std::string ylabel = options.log_scale ? "elements (log scale)" : "elements";
  img.text_vertical(14, top + ph / 2 - RgbImage::text_width(ylabel, 2) / 2, ylabel, ink, 2);
  return img;
}

std::string histogram_png(const MetricSummary& s, const HistogramPlotOptions& options) {
  return encode_png(histogram_image(s, options));
}

}  // namespace isohex
