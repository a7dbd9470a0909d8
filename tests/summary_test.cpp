// Quality summaries: classes, histogram bins, worst elements, JSON and the SVG figure.
#include "isohex/quality/summary.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

using namespace isohex;

TEST(Summary, ScaledJacobianClassesAndDegenerate) {
  const std::vector<double> v = {1.0, 0.5, 0.2, 0.19999999999999998, 0.0, -0.1, -1.0, kVerdictDblMax, 0.95};
  const MetricSummary s = summarize(HexMetric::scaled_jacobian, v, 3);
  EXPECT_EQ(s.count, 9u);
  EXPECT_EQ(s.degenerate, 1u);
  EXPECT_EQ(s.inverted, 2u);       // -0.1, -1
  EXPECT_EQ(s.questionable, 2u);   // 0.19999999999999998, 0.0 (0.2 itself is acceptable)
  EXPECT_DOUBLE_EQ(s.min, -1.0);
  EXPECT_DOUBLE_EQ(s.max, 1.0);    // the 1e30 marker never counts as the best element
  EXPECT_DOUBLE_EQ(s.mean, (1.0 + 0.5 + 0.2 + 0.19999999999999998 + 0.0 - 0.1 - 1.0 + 0.95) / 8);
  ASSERT_EQ(s.worst.size(), 3u);
  EXPECT_EQ(s.worst[0].id, 7);     // degenerate first
  EXPECT_EQ(s.worst[1].id, 6);
  EXPECT_EQ(s.worst[2].id, 5);
}

TEST(Summary, HistogramBinsAreHalfOpenWithExactEdges) {
  const std::vector<double> v = {-1.0, -0.95, 0.0, 0.1, 0.19999999999999998, 0.2, 0.3, 0.7, 1.0, 1.0};
  const MetricSummary s = summarize(HexMetric::scaled_jacobian, v);
  const Histogram& h = s.histogram;
  ASSERT_EQ(h.counts.size(), 20u);
  EXPECT_EQ(h.counts[0], 2u);   // [-1, -0.9)
  EXPECT_EQ(h.counts[10], 1u);  // [0, 0.1)
  EXPECT_EQ(h.counts[11], 2u);  // [0.1, 0.2): 0.1 and 0.19999999999999998
  EXPECT_EQ(h.counts[12], 1u);  // [0.2, 0.3)
  EXPECT_EQ(h.counts[13], 1u);  // 0.3 (edges[13] is 0.3 exactly as 3/10.0)
  EXPECT_EQ(h.counts[19], 2u);  // [0.9, 1]: the last bin keeps its right edge
  std::size_t total = 0;
  for (auto c : h.counts) total += c;
  EXPECT_EQ(total + h.below + h.above, v.size());
}

TEST(Summary, LowerIsBetterMetricsListHighValuesAsWorst) {
  const std::vector<double> v = {1.0, 3.0, 1.5, 2.0};
  const MetricSummary s = summarize(HexMetric::edge_ratio, v, 2);
  ASSERT_EQ(s.worst.size(), 2u);
  EXPECT_EQ(s.worst[0].id, 1);
  EXPECT_EQ(s.worst[1].id, 3);
  EXPECT_EQ(s.histogram.edges.front(), 1.0);
  EXPECT_EQ(s.histogram.edges.back(), 3.0);
}

TEST(Summary, JsonCarriesTheCounts) {
  const MetricSummary s = summarize(HexMetric::scaled_jacobian, {0.1, -0.5, 0.9});
  const nlohmann::json j = to_json(s);
  EXPECT_EQ(j["metric"], "scaled_jacobian");
  EXPECT_EQ(j["inverted"], 1);
  EXPECT_EQ(j["questionable"], 1);
  EXPECT_EQ(j["histogram"]["counts"].size(), 20u);
  EXPECT_EQ(j["worst"][0]["id"], 1);
}

TEST(Summary, SvgHasOneBarPerNonEmptyBin) {
  const MetricSummary s = summarize(HexMetric::scaled_jacobian, {0.1, -0.5, 0.9, 0.95, 0.91});
  for (bool log : {false, true}) {
    HistogramPlotOptions opt;
    opt.log_scale = log;
    opt.title = "a <title> & more";
    const std::string svg = histogram_svg(s, opt);
    std::size_t rects = 0;
    for (std::size_t p = svg.find("<rect x="); p != std::string::npos; p = svg.find("<rect x=", p + 1)) ++rects;
    EXPECT_EQ(rects, 3u);
    EXPECT_NE(svg.find("a &lt;title&gt; &amp; more"), std::string::npos);
    EXPECT_NE(svg.find("#cc3311"), std::string::npos);  // the inverted bar is red
    EXPECT_EQ(svg.find("nan"), std::string::npos);
  }
}

TEST(Summary, EmptyMeshIsHarmless) {
  const MetricSummary s = summarize(HexMetric::scaled_jacobian, {});
  EXPECT_EQ(s.count, 0u);
  EXPECT_TRUE(s.worst.empty());
  EXPECT_FALSE(histogram_svg(s).empty());
}

TEST(Summary, TallestBarStaysInsideThePlot) {
  std::vector<double> v(3500, 0.95);
  v.push_back(0.1);
  const std::string svg = histogram_svg(summarize(HexMetric::scaled_jacobian, v));
  // Every bar's top edge (y attribute) is at or below the plot's top margin (y = 60).
  for (std::size_t p = svg.find("<rect x="); p != std::string::npos; p = svg.find("<rect x=", p + 1)) {
    const std::size_t y = svg.find("y=\"", p) + 3;
    EXPECT_GE(std::stod(svg.substr(y, 12)), 60.0 - 1e-9);
  }
}
