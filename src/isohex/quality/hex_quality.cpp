// Metric names and dispatch by enum.
#include "isohex/quality/hex_quality.hpp"

#include "isohex/error.hpp"
#include "isohex/quality/jacobian_bounds.hpp"

namespace isohex {

std::string_view metric_name(HexMetric m) {
  switch (m) {
    case HexMetric::scaled_jacobian: return "scaled_jacobian";
    case HexMetric::jacobian: return "jacobian";
    case HexMetric::edge_ratio: return "edge_ratio";
    case HexMetric::mean_ratio: return "mean_ratio";
    case HexMetric::shape: return "shape";
    case HexMetric::skew: return "skew";
    case HexMetric::taper: return "taper";
    case HexMetric::volume: return "volume";
    case HexMetric::jacobian_ratio: return "jacobian_ratio";
    case HexMetric::gauss_jacobian: return "gauss_jacobian";
  }
  throw Error("unknown hex metric");
}

std::optional<HexMetric> metric_from_name(std::string_view name) {
  for (HexMetric m : kAllHexMetrics)
    if (metric_name(m) == name) return m;
  return std::nullopt;
}

double hex_metric(HexMetric m, const std::array<Vec3, 8>& p) {
  switch (m) {
    case HexMetric::scaled_jacobian: return scaled_jacobian(p);
    case HexMetric::jacobian: return jacobian(p);
    case HexMetric::edge_ratio: return edge_ratio(p);
    case HexMetric::mean_ratio: return mean_ratio(p);
    case HexMetric::shape: return shape(p);
    case HexMetric::skew: return skew(p);
    case HexMetric::taper: return taper(p);
    case HexMetric::volume: return volume(p);
    case HexMetric::jacobian_ratio: return jacobian_ratio(p);
    case HexMetric::gauss_jacobian: return gauss_min_jacobian(p);
  }
  throw Error("unknown hex metric");
}

}  // namespace isohex
