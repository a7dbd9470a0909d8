#pragma once
/// \file plot_detail.hpp
/// \brief Small helpers shared by the quality figures (SVG and PNG histograms) and the HTML
/// report. Internal.

#include "isohex/quality/summary.hpp"

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace isohex::detail {

/// Tick values for a linear count axis: 1, 2 or 5 times a power of ten, about 5 ticks, up to
/// the first at or above `top` (so the tallest bar stays inside the plot).
std::vector<double> linear_ticks(double top);

/// The count axis of a histogram: count → height as a fraction of the plot.
struct CountAxis {
  CountAxis(const MetricSummary& s, bool log_scale);
  /// Linear: count / the top tick. Log: a count c > 0 sits at (1 + log10 c) / (1 + decades),
  /// so one element stays visible.
  [[nodiscard]] double frac(double count) const;
  std::vector<double> ticks;  ///< linear ticks (linear_ticks of the tallest bar)
  double decades = 0;         ///< powers of ten up to the tallest bar (log axis)
  bool log_scale = false;
};

/// Bar colour of the bin starting at `lo`, "#rrggbb": red below 0, orange below 0.2, green
/// (scaled Jacobian); blue for other metrics. The SVG and PNG figures share it.
const char* bar_colour(const MetricSummary& s, double lo);

/// `s` with <, >, & and " escaped, for XML/HTML text and attribute values.
std::string escape_markup(std::string_view s);

}  // namespace isohex::detail
