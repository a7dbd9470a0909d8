// isohex-report-demo DIR [--n N] [--max-hexes K] [--title T]: writes the quality report of
// a synthetic two-stage run into DIR, for tests/oracle/test_report_chromium.py (until
// `isohex mesh --report` is wired up) and for looking at the page by hand.
//
// "extraction" is a ball of N³ hexes with a strong jitter (many inverted hexes), the final
// "optimization" stage the same ball with a small jitter (a few inverted hexes left), so the
// page has every colour class to show.
#include "isohex/mesh/generate.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/report.hpp"

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

int main(int argc, char** argv) {
  using namespace isohex;
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s DIR [--n N] [--max-hexes K] [--title T]\n", argv[0]);
    return 2;
  }
  int n = 14;
  ReportInput in;
  in.title = "isohex report demo: jittered ball";
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string opt = argv[i];
    if (opt == "--n") n = std::atoi(argv[i + 1]);
    else if (opt == "--max-hexes") in.viewer.max_hexes = static_cast<std::size_t>(std::atoll(argv[i + 1]));
    else if (opt == "--title") in.title = argv[i + 1];
    else {
      std::fprintf(stderr, "unknown option %s\n", opt.c_str());
      return 2;
    }
  }
  try {
    const HexMesh ball = ball_mesh(n);
    HexMesh rough = ball, fine = ball;
    const double h = 2.0 / n;  // grid spacing of the ball's cube before mapping
    jitter(rough, 0.3 * h, 11);
    jitter(fine, 0.12 * h, 5);

    ReportStage a{"extraction", scaled_jacobians(rough), rough.hexes.size(), rough.points.size(), 0.125, {}};
    a.extra = {{"jitter", 0.3}};
    ReportStage b{"optimization", scaled_jacobians(fine), fine.hexes.size(), fine.points.size(), 0.5, {}};
    b.extra = {{"jitter", 0.12}, {"seed", 5}};
    in.stages = {a, b};
    in.summary = {{"input", "ball_mesh(" + std::to_string(n) + ")"},
                  {"options", {{"n", n}, {"seeds", {11, 5}}}},
                  {"note", "synthetic data from tests/report_demo.cpp"}};
    in.mesh = &fine;
    const ReportFiles files = write_report(argv[1], in);
    for (const auto& f : files.files) std::printf("%s\n", f.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "report demo: %s\n", e.what());
    return 1;
  }
  return 0;
}
