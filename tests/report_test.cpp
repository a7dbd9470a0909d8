// The quality report: PNG encoding (decoded again here with zlib), the raster histogram,
// the viewer's embedded data, and write_report()'s files (complete, deterministic, offline).
#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/mesh/generate.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/quality/report.hpp"
#include "isohex/quality/report_detail.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <optional>
#include <regex>
#include <set>

using namespace isohex;
namespace fs = std::filesystem;

namespace {

std::uint32_t be32(const std::string& s, std::size_t at) {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(s[at])) << 24 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 1])) << 16 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 2])) << 8 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 3]));
}

std::string inflate_all(const std::string& packed, std::size_t expected) {
  std::string out(expected + 1, '\0');  // one spare byte: a longer stream shows as a size mismatch
  uLongf size = static_cast<uLongf>(out.size());
  const int rc = uncompress(reinterpret_cast<Bytef*>(out.data()), &size, reinterpret_cast<const Bytef*>(packed.data()),
                            static_cast<uLong>(packed.size()));
  EXPECT_EQ(rc, Z_OK);
  out.resize(size);
  return out;
}

// A minimal PNG reader for what encode_png() writes: checks signature, chunk order and CRCs,
// IHDR, and that every scanline uses filter 0; returns the RGB bytes.
std::string decode_png(const std::string& png, int& width, int& height) {
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  std::size_t at = 8;
  std::vector<std::string> order;
  std::string idat;
  while (at + 12 <= png.size()) {
    const std::uint32_t len = be32(png, at);
    const std::string type = png.substr(at + 4, 4);
    const std::string data = png.substr(at + 8, len);
    const uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(png.data() + at + 4), len + 4);
    EXPECT_EQ(be32(png, at + 8 + len), static_cast<std::uint32_t>(crc)) << "CRC of " << type;
    order.push_back(type);
    if (type == "IHDR") {
      width = static_cast<int>(be32(data, 0));
      height = static_cast<int>(be32(data, 4));
      EXPECT_EQ(data.substr(8), std::string("\x08\x02\0\0\0", 5));
    }
    if (type == "IDAT") idat += data;
    at += 12 + len;
  }
  EXPECT_EQ(at, png.size());
  EXPECT_EQ(order, (std::vector<std::string>{"IHDR", "IDAT", "IEND"}));
  const auto row = static_cast<std::size_t>(1 + 3 * width);
  const std::string raw = inflate_all(idat, row * static_cast<std::size_t>(height));
  EXPECT_EQ(raw.size(), row * static_cast<std::size_t>(height));
  std::string rgb;
  for (std::size_t y = 0; y + 1 <= raw.size() / row; ++y) {
    EXPECT_EQ(raw[y * row], '\0');
    rgb += raw.substr(y * row + 1, row - 1);
  }
  return rgb;
}

// Runs of consecutive columns holding a pixel of one of `colours`: the histogram's bars.
struct Bar {
  int x0, x1, top;
  Rgb colour;
};
std::vector<Bar> find_bars(const RgbImage& img, const std::vector<Rgb>& colours) {
  std::vector<Bar> bars;
  for (int x = 0; x < img.width(); ++x) {
    std::optional<Rgb> found;
    int top = img.height();
    for (int y = 0; y < img.height(); ++y)
      if (std::find(colours.begin(), colours.end(), img.at(x, y)) != colours.end()) {
        found = img.at(x, y);
        top = std::min(top, y);
      }
    if (!found) continue;
    if (!bars.empty() && bars.back().x1 == x - 1 && bars.back().colour == *found) {
      bars.back().x1 = x;
      bars.back().top = std::min(bars.back().top, top);
    } else {
      bars.push_back({x, x, top, *found});
    }
  }
  return bars;
}

// Values that fill chosen scaled-Jacobian bins: counts[i] values in [-1 + 0.1 i, ...).
std::vector<double> values_for(const std::vector<std::size_t>& counts) {
  std::vector<double> v;
  for (std::size_t i = 0; i < counts.size(); ++i)
    for (std::size_t k = 0; k < counts[i]; ++k) v.push_back(-1 + 0.1 * static_cast<double>(i) + 0.05);
  return v;
}

}  // namespace

TEST(ReportPng, EncodesWhatWasDrawnLosslessly) {
  RgbImage img(37, 23, {10, 20, 30});
  img.fill_rect(3, 4, 20, 9, {200, 100, 0});
  img.set(36, 22, {1, 2, 3});
  img.text(2, 12, "SJ -0.25", {255, 255, 255});
  img.fill_rect(-5, -5, 2, 2, {9, 9, 9});  // clipped, not a crash
  int w = 0, h = 0;
  const std::string rgb = decode_png(encode_png(img), w, h);
  EXPECT_EQ(w, 37);
  EXPECT_EQ(h, 23);
  ASSERT_EQ(rgb.size(), img.pixels().size());
  EXPECT_TRUE(std::equal(rgb.begin(), rgb.end(), img.pixels().begin(),
                         [](char a, std::uint8_t b) { return static_cast<std::uint8_t>(a) == b; }));
  EXPECT_EQ(img.at(36, 22), (Rgb{1, 2, 3}));
  EXPECT_EQ(img.at(0, 0), (Rgb{9, 9, 9}));
  EXPECT_EQ(encode_png(img), encode_png(img));
}

TEST(ReportPng, FontCoversTheFigureLabels) {
  for (char c : std::string("0123456789 abcdefghijklmnopqrstuvwxyz.,-+:()[]<>=/%_'?|")) EXPECT_TRUE(font_has_glyph(c)) << c;
  EXPECT_FALSE(font_has_glyph('@'));
  // A glyph is drawn where text() says: "1" has ink in its middle column, " " has none.
  RgbImage img(20, 10);
  img.text(0, 0, "1 ", {0, 0, 0}, 1);
  int ink_one = 0, ink_space = 0;
  for (int y = 0; y < 7; ++y)
    for (int x = 0; x < 12; ++x) (x < 6 ? ink_one : ink_space) += img.at(x, y) == Rgb{0, 0, 0};
  EXPECT_GT(ink_one, 7);
  EXPECT_EQ(ink_space, 0);
  EXPECT_EQ(RgbImage::text_width("abc", 2), 34);
  EXPECT_EQ(rgb_from_hex("#cc3311"), (Rgb{0xcc, 0x33, 0x11}));
  EXPECT_THROW(rgb_from_hex("cc3311"), std::invalid_argument);
}

TEST(ReportPng, HistogramBarsMatchCountsAndClasses) {
  // Bins: 2 inverted ones, one questionable, two acceptable; one bin holds a single hex,
  // which must still show next to 400.
  std::vector<std::size_t> counts(20, 0);
  counts[3] = 1, counts[8] = 100, counts[11] = 50, counts[14] = 400, counts[19] = 200;
  const MetricSummary s = summarize(HexMetric::scaled_jacobian, values_for(counts));
  ASSERT_EQ(s.histogram.counts, counts);
  const RgbImage img = histogram_image(s, {"test figure", false});
  const Rgb red = rgb_from_hex("#cc3311"), orange = rgb_from_hex("#ee7733"), green = rgb_from_hex("#228833");
  const std::vector<Bar> bars = find_bars(img, {red, orange, green});
  ASSERT_EQ(bars.size(), 5u);
  const std::vector<Rgb> expected_colour = {red, red, orange, green, green};
  const std::vector<std::size_t> nonzero = {1, 100, 50, 400, 200};
  for (std::size_t i = 0; i < bars.size(); ++i) {
    EXPECT_EQ(bars[i].colour, expected_colour[i]) << "bar " << i;
    EXPECT_GE(bars[i].x1 - bars[i].x0, 20) << "bar " << i;  // ~39 px per bin
    if (i > 0) EXPECT_LT(bars[i - 1].x1, bars[i].x0);
  }
  // Bars are in bin order and heights proportional to counts (all bars share the baseline).
  int baseline = 0;
  for (int y = img.height() - 1; y >= 0 && baseline == 0; --y)
    if (img.at((bars[3].x0 + bars[3].x1) / 2, y) == green) baseline = y + 1;
  const double h400 = baseline - bars[3].top;
  EXPECT_GT(h400, 250);
  EXPECT_NEAR((baseline - bars[1].top) / h400, 100.0 / 400, 0.01);
  EXPECT_NEAR((baseline - bars[4].top) / h400, 200.0 / 400, 0.01);
  EXPECT_GE(baseline - bars[0].top, 1);
  const double bin = (bars[4].x0 - bars[3].x0) / 5.0;  // bins 14 and 19
  EXPECT_NEAR((bars[1].x0 - bars[0].x0) / bin, 5.0, 0.1);  // bins 3 and 8
  // Deterministic bytes.
  EXPECT_EQ(histogram_png(s, {"test figure", true}), histogram_png(s, {"test figure", true}));
}

TEST(ReportViewer, CompleteMeshEmbedsEveryQuadFacingOutOfItsFirstSide) {
  const HexMesh m = box_mesh(3, 3, 3, Vec3(100, 100, 100), Vec3(103, 106, 109));
  const ViewerMesh v = viewer_mesh(m, scaled_jacobians(m), {});
  EXPECT_TRUE(v.complete);
  EXPECT_EQ(v.sj.size(), 27u);
  EXPECT_EQ(v.quads.size() / 4, build_quads(m).size());
  EXPECT_EQ(v.points.size(), m.points.size() * 3);
  std::size_t one_sided = 0;
  for (std::size_t q = 0; q < v.sides.size() / 2; ++q) {
    const std::int32_t a = v.sides[2 * q], b = v.sides[2 * q + 1];
    ASSERT_GE(a, 0);
    one_sided += b < 0;
    // Normal by the diagonals, against the direction from the cell's centroid to the quad.
    auto P = [&](int i) {
      const std::uint32_t p = v.quads[4 * q + static_cast<std::size_t>(i)];
      return Vec3(v.points[3 * p], v.points[3 * p + 1], v.points[3 * p + 2]);
    };
    const Vec3 n = (P(2) - P(0)).cross(P(3) - P(1));
    const Vec3 c(v.centroids[3 * a], v.centroids[3 * a + 1], v.centroids[3 * a + 2]);
    EXPECT_GT(n.dot((P(0) + P(1) + P(2) + P(3)) / 4 - c), 0) << "quad " << q;
  }
  EXPECT_EQ(one_sided, boundary_quads(m).size());
  // Centred and scaled to radius 1: the box corners land on the unit sphere.
  double rmax = 0;
  for (std::size_t p = 0; p < v.points.size(); p += 3)
    rmax = std::max(rmax, Vec3(v.points[p], v.points[p + 1], v.points[p + 2]).norm());
  EXPECT_NEAR(rmax, 1.0, 1e-6);
  for (float s : v.sj) EXPECT_NEAR(s, 1.0f, 1e-6f);
}

TEST(ReportViewer, LargeMeshEmbedsBoundaryAndWorstHexes) {
  HexMesh m = ball_mesh(8);
  jitter(m, 0.06, 3);
  const std::vector<double> sj = scaled_jacobians(m);
  ReportViewerLimits lim;
  lim.max_hexes = 100;
  lim.max_worst_hexes = 7;
  const ViewerMesh v = viewer_mesh(m, sj, lim);
  EXPECT_FALSE(v.complete);
  EXPECT_EQ(v.mesh_hexes, m.hexes.size());
  ASSERT_EQ(v.worst_hexes, 7u);
  // The 7 lowest scaled Jacobians are among the cells, as whole hexes (6 quads each).
  std::vector<Index> order(m.hexes.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<Index>(i);
  std::sort(order.begin(), order.end(), [&](Index a, Index b) { return sj[a] != sj[b] ? sj[a] < sj[b] : a < b; });
  ASSERT_LT(sj[order[6]], kQuestionableSJ);
  std::map<Index, std::int32_t> cell;
  for (std::size_t c = 0; c < v.cell_hex.size(); ++c) cell[v.cell_hex[c]] = static_cast<std::int32_t>(c);
  for (int k = 0; k < 7; ++k) {
    ASSERT_TRUE(cell.count(order[k])) << k;
    const std::int32_t c = cell[order[k]];
    EXPECT_FLOAT_EQ(v.sj[c], static_cast<float>(sj[order[k]]));
    EXPECT_EQ(std::count(v.sides.begin(), v.sides.end(), c), 6) << k;
  }
  // The quads are the boundary quads and the faces of the worst hexes, in build_quads order;
  // a side is a cell only for a worst hex or the owner of a boundary quad.
  std::set<Index> worst(order.begin(), order.begin() + 7);
  std::vector<std::array<std::int32_t, 2>> expected;
  for (const QuadFace& q : build_quads(m)) {
    const bool w0 = worst.count(q.hex[0]) > 0, w1 = q.hex[1] >= 0 && worst.count(q.hex[1]) > 0;
    if (!q.is_boundary() && !w0 && !w1) continue;
    expected.push_back({w0 || q.is_boundary() ? cell.at(q.hex[0]) : -1, w1 ? cell.at(q.hex[1]) : -1});
  }
  ASSERT_EQ(v.sides.size(), 2 * expected.size());
  for (std::size_t q = 0; q < expected.size(); ++q) {
    EXPECT_EQ(v.sides[2 * q], expected[q][0]) << q;
    EXPECT_EQ(v.sides[2 * q + 1], expected[q][1]) << q;
  }
  EXPECT_GT(expected.size(), boundary_quads(m).size());
  EXPECT_LT(v.sj.size(), m.hexes.size());
}

TEST(ReportBase64, MatchesRfc4648Vectors) {
  using report_detail::base64_encode;
  EXPECT_EQ(base64_encode(""), "");
  EXPECT_EQ(base64_encode("f"), "Zg==");
  EXPECT_EQ(base64_encode("fo"), "Zm8=");
  EXPECT_EQ(base64_encode("foo"), "Zm9v");
  EXPECT_EQ(base64_encode("foob"), "Zm9vYg==");
  EXPECT_EQ(base64_encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64_encode("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64_encode(std::string("\xff\xfe\x00", 3)), "//4A");
}

namespace {

ReportInput demo_input(const HexMesh& final_mesh, const HexMesh& first) {
  ReportInput in;
  in.title = "demo <&> \"report\"";
  in.summary = {{"input", "ball"}, {"options", {{"n", 6}, {"flags", {1, 2}}}}, {"edits", std::vector<int>(50, 1)}};
  in.stages.push_back({"extraction", scaled_jacobians(first), 0, first.points.size(), 0.25, {{"rounds", 3}}});
  in.stages.push_back({"surface smoothing", scaled_jacobians(final_mesh), 0, final_mesh.points.size(), -1, {}});
  in.mesh = &final_mesh;
  return in;
}

std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST(Report, WritesEveryFileDeterministicallyAndNothingElse) {
  HexMesh first = ball_mesh(6), last = ball_mesh(6);
  jitter(first, 0.1, 1);
  jitter(last, 0.03, 2);
  const ReportInput in = demo_input(last, first);
  const fs::path dir = test::scratch_dir();
  const ReportFiles files = write_report(dir / "a" / "nested", in);
  write_report(dir / "b", in);
  std::vector<std::string> expected = files.files;
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(listing(dir / "a" / "nested"), expected);  // no temporary files left behind
  EXPECT_EQ(expected, (std::vector<std::string>{"histogram-1-extraction.png", "histogram-1-extraction.svg",
                                                "histogram-2-surface-smoothing.png", "histogram-2-surface-smoothing.svg",
                                                "report.html", "report.json"}));
  for (const auto& f : files.files)
    EXPECT_EQ(io::read_file(dir / "a" / "nested" / f), io::read_file(dir / "b" / f)) << f << " differs between runs";

  const auto j = nlohmann::json::parse(io::read_file(dir / "b" / "report.json"));
  EXPECT_EQ(j["format"], "isohex-report");
  EXPECT_EQ(j["summary"], in.summary);
  ASSERT_EQ(j["stages"].size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    const MetricSummary s = summarize(HexMetric::scaled_jacobian, in.stages[k].sj);
    EXPECT_EQ(j["stages"][k]["scaled_jacobian"], to_json(s));
    EXPECT_EQ(j["stages"][k]["hexes"], in.stages[k].sj.size());
  }
  EXPECT_EQ(j["stages"][0]["seconds"], 0.25);
  EXPECT_FALSE(j["stages"][1].contains("seconds"));
  EXPECT_EQ(j["viewer"]["cells"], last.hexes.size());
  EXPECT_EQ(j["viewer"]["complete"], true);

  // The SVG is the library's own figure; the PNG decodes to the figure's size.
  EXPECT_EQ(io::read_file(dir / "b" / "histogram-1-extraction.svg"),
            histogram_svg(summarize(HexMetric::scaled_jacobian, in.stages[0].sj), {"1. extraction: scaled Jacobian", false}));
  int w = 0, h = 0;
  decode_png(io::read_file(dir / "b" / "histogram-2-surface-smoothing.png"), w, h);
  EXPECT_EQ(w, histogram_image(summarize(HexMetric::scaled_jacobian, in.stages[1].sj)).width());
  EXPECT_GT(h, 300);
}

TEST(Report, PageIsSelfContainedAndCarriesTheViewerData) {
  HexMesh first = ball_mesh(5), last = ball_mesh(5);
  jitter(first, 0.1, 1);
  const ReportInput in = demo_input(last, first);
  const fs::path dir = test::scratch_dir();
  write_report(dir, in);
  const std::string html = io::read_file(dir / "report.html");
  // Nothing fetched: no external scripts, styles, images or imports (the SVG namespace
  // attribute is a name, not a request).
  EXPECT_FALSE(std::regex_search(html, std::regex(R"((src|href)\s*=\s*["']?\s*(https?:|//))", std::regex::icase)));
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_EQ(html.find("@import"), std::string::npos);
  EXPECT_EQ(html.find("url("), std::string::npos);
  // The title is escaped; both figures are inline; the stage names appear in the table.
  EXPECT_NE(html.find("<h1>demo &lt;&amp;&gt; &quot;report&quot;</h1>"), std::string::npos);
  EXPECT_EQ(std::count(html.begin(), html.end(), '\0'), 0);
  std::size_t svgs = 0;
  for (std::size_t at = html.find("<svg "); at != std::string::npos; at = html.find("<svg ", at + 1)) ++svgs;
  EXPECT_EQ(svgs, 2u);
  EXPECT_NE(html.find("<td class=\"l\">surface smoothing</td>"), std::string::npos);
  EXPECT_NE(html.find("[50 entries, in report.json]"), std::string::npos);
  EXPECT_NE(html.find("<canvas id=\"viewer\""), std::string::npos);

  // The embedded blob inflates to the layout that mesh-info announces, and holds the same
  // numbers as viewer_mesh().
  const std::string open = "<script type=\"application/octet-stream\" id=\"mesh-data\">\n";
  const std::size_t a = html.find(open), b = html.find("\n</script>", a);
  ASSERT_NE(a, std::string::npos);
  const std::string b64 = html.substr(a + open.size(), b - a - open.size());
  const ViewerMesh v = viewer_mesh(last, in.stages.back().sj, in.viewer);
  EXPECT_EQ(b64, report_detail::viewer_payload(v));
  const std::size_t info_at = html.find("id=\"mesh-info\">");
  const auto info = nlohmann::json::parse(html.substr(info_at + 15, html.find("</script>", info_at) - info_at - 15));
  EXPECT_EQ(info, report_detail::viewer_info(v));
  // Decode the base64 independently of the encoder (a 6-bit table), then inflate.
  std::string packed;
  std::uint32_t acc = 0;
  int bits = 0;
  for (char c : b64) {
    const auto pos = std::string("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/").find(c);
    if (pos == std::string::npos) break;
    acc = acc << 6 | static_cast<std::uint32_t>(pos);
    bits += 6;
    if (bits >= 8) packed.push_back(static_cast<char>((acc >> (bits - 8)) & 0xff)), bits -= 8;
  }
  const std::string raw = inflate_all(packed, info["bytes"].get<std::size_t>());
  ASSERT_EQ(raw.size(), info["bytes"].get<std::size_t>());
  const std::size_t sj_at = raw.size() - 4 * v.sj.size();
  for (std::size_t c = 0; c < v.sj.size(); ++c) {
    float f;
    std::memcpy(&f, raw.data() + sj_at + 4 * c, 4);
    EXPECT_EQ(f, v.sj[c]);
  }
}

TEST(Report, RejectsInconsistentInput) {
  const HexMesh m = box_mesh(2, 2, 2);
  ReportInput in;
  const fs::path dir = test::scratch_dir();
  EXPECT_THROW(write_report(dir / "none", in), Error);
  in.stages.push_back({"only", std::vector<double>(3, 1.0), 0, 0, -1, {}});
  in.mesh = &m;  // 8 hexes, 3 values
  EXPECT_THROW(write_report(dir / "bad", in), Error);
  in.mesh = nullptr;
  EXPECT_NO_THROW(write_report(dir / "ok", in));
  EXPECT_EQ(io::read_file(dir / "ok" / "report.html").find("mesh-data"), std::string::npos);
}
