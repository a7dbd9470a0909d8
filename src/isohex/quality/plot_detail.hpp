#pragma once
/// \file plot_detail.hpp
/// \brief Small helpers shared by the quality figures (SVG and PNG histograms) and the HTML
/// report. Internal.

#include <string>
#include <string_view>
#include <vector>

namespace isohex::detail {

/// Tick values for a linear count axis: 1, 2 or 5 times a power of ten, about 5 ticks, up to
/// the first at or above `top` (so the tallest bar stays inside the plot).
std::vector<double> linear_ticks(double top);

/// `s` with <, >, & and " escaped, for XML/HTML text and attribute values.
std::string escape_markup(std::string_view s);

}  // namespace isohex::detail
