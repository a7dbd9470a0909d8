#include "isohex/quality/summary.hpp"

#include "isohex/quality/jacobian_bounds.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace isohex {

bool higher_is_better(HexMetric m) {
  switch (m) {
    case HexMetric::edge_ratio:
    case HexMetric::skew:
    case HexMetric::taper: return false;
    default: return true;
  }
}

namespace {

Histogram make_histogram(HexMetric m, const std::vector<double>& values, double lo, double hi) {
  Histogram h;
  if (m == HexMetric::scaled_jacobian || m == HexMetric::jacobian_ratio) {
    for (int i = -10; i <= 10; ++i) h.edges.push_back(i / 10.0);
  } else {
    if (!(hi > lo)) hi = lo + 1;  // one value (or none): a unit-wide range around it
    for (int i = 0; i <= 20; ++i) h.edges.push_back(lo + (hi - lo) * i / 20.0);
  }
  h.counts.assign(h.edges.size() - 1, 0);
  const double first = h.edges.front(), last = h.edges.back();
  const double width = (last - first) / static_cast<double>(h.counts.size());
  for (double v : values) {
    if (is_degenerate(v)) continue;
    if (v < first) {
      ++h.below;
    } else if (v > last) {
      ++h.above;
    } else {
      auto i = static_cast<std::size_t>((v - first) / width);
      i = std::min(i, h.counts.size() - 1);
      // Rounding in the division can land a value one bin off its edges: fix it exactly.
      while (i > 0 && v < h.edges[i]) --i;
      while (i + 1 < h.counts.size() && v >= h.edges[i + 1]) ++i;
      ++h.counts[i];
    }
  }
  return h;
}

}  // namespace

MetricSummary summarize(HexMetric m, const std::vector<double>& values, std::size_t worst) {
  MetricSummary s;
  s.metric = m;
  s.count = values.size();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, sum = 0;
  for (double v : values) {
    if (is_degenerate(v)) {
      ++s.degenerate;
      continue;
    }
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    sum += v;
    if (m == HexMetric::scaled_jacobian) {
      if (v < 0) ++s.inverted;
      else if (v < kQuestionableSJ) ++s.questionable;
    } else if (m == HexMetric::jacobian_ratio) {
      if (v <= 0) ++s.inverted;
      else if (v < kPoorJacobianRatio) ++s.questionable;
    }
  }
  const std::size_t good = s.count - s.degenerate;
  if (good > 0) {
    s.min = lo;
    s.max = hi;
    s.mean = sum / static_cast<double>(good);
  }
  s.histogram = make_histogram(m, values, s.min, s.max);

  // Worst elements: degenerate first, then by value (ties by id, for a stable report).
  std::vector<ElementValue> all(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) all[i] = {static_cast<Index>(i), values[i]};
  const bool up = higher_is_better(m);
  auto worse = [up](const ElementValue& a, const ElementValue& b) {
    const bool da = is_degenerate(a.value), db = is_degenerate(b.value);
    if (da != db) return da;
    if (a.value != b.value) return up ? a.value < b.value : a.value > b.value;
    return a.id < b.id;
  };
  const std::size_t k = std::min(worst, all.size());
  std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(k), all.end(), worse);
  s.worst.assign(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(k));
  return s;
}

QuadSummary summarize_quads(const HexMesh& mesh, const std::vector<Quad>& quads) {
  std::vector<double> sj(quads.size());
  tbb::parallel_for(std::size_t{0}, quads.size(), [&](std::size_t i) {
    const Quad& q = quads[i];
    sj[i] = quad_scaled_jacobian({mesh.points[q[0]], mesh.points[q[1]], mesh.points[q[2]], mesh.points[q[3]]});
  });
  QuadSummary s;
  s.count = quads.size();
  if (quads.empty()) return s;
  s.min = std::numeric_limits<double>::infinity();
  double sum = 0;
  for (double v : sj) {
    s.min = std::min(s.min, v);
    sum += v;
    s.below += v < kQuestionableSJ;
  }
  s.mean = sum / static_cast<double>(quads.size());
  return s;
}

nlohmann::json to_json(const MetricSummary& s) {
  nlohmann::json j;
  j["metric"] = std::string(metric_name(s.metric));
  j["elements"] = s.count;
  j["degenerate"] = s.degenerate;
  j["min"] = s.min;
  j["mean"] = s.mean;
  j["max"] = s.max;
  if (s.metric == HexMetric::scaled_jacobian) {
    j["inverted"] = s.inverted;
    j["questionable"] = s.questionable;
    j["questionable_threshold"] = kQuestionableSJ;
  } else if (s.metric == HexMetric::jacobian_ratio) {
    j["not_valid_inside"] = s.inverted;
    j["poor"] = s.questionable;
    j["poor_threshold"] = kPoorJacobianRatio;
  }
  j["histogram"] = {{"edges", s.histogram.edges},
                    {"counts", s.histogram.counts},
                    {"below", s.histogram.below},
                    {"above", s.histogram.above}};
  nlohmann::json w = nlohmann::json::array();
  for (const auto& e : s.worst) w.push_back({{"id", e.id}, {"value", e.value}});
  j["worst"] = w;
  return j;
}

ValiditySummary summarize_validity(const HexMesh& mesh, std::size_t keep) {
  return summarize_validity(mesh_jacobians(mesh), keep);
}

ValiditySummary summarize_validity(const MeshJacobians& mj, std::size_t keep) {
  ValiditySummary s;
  s.hexes = mj.valid.size();
  for (std::size_t h = 0; h < mj.valid.size(); ++h) {
    s.gauss_nonpositive += !(mj.gauss_min[h] > 0);
    s.min_ratio = std::min(s.min_ratio, mj.ratio[h]);
    if (mj.valid[h]) {
      s.poor += mj.ratio[h] < kPoorJacobianRatio;
      continue;
    }
    if (s.not_valid_inside++ < keep) s.invalid.push_back(static_cast<Index>(h));
  }
  return s;
}

std::string describe(const ValiditySummary& s) {
  return fmt::format("validity inside (certified Bernstein bounds of det J): {} of {} hexes not valid inside, {} with "
                     "det J <= 0 at a Gauss point; jacobian ratio min {:.4g}; valid inside with a ratio below {}: {}",
                     s.not_valid_inside, s.hexes, s.gauss_nonpositive, s.min_ratio, kPoorJacobianRatio, s.poor);
}

nlohmann::json to_json(const ValiditySummary& s) {
  return {{"hexes", s.hexes},
          {"certified_valid", s.hexes - s.not_valid_inside},
          {"not_valid_inside", s.not_valid_inside},
          {"not_valid_inside_hexes", s.invalid},
          {"gauss_nonpositive", s.gauss_nonpositive},
          {"jacobian_ratio_min", s.min_ratio},
          {"jacobian_ratio_poor", s.poor},
          {"poor_threshold", kPoorJacobianRatio}};
}

}  // namespace isohex
