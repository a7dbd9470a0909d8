// Refinement throughput (items/s = output hexes/s) of isohex::refine on a 60^3 box grid:
// a ball of marked vertices in the middle (full templates inside, transitions around it), and
// every vertex marked (uniform 27-subdivision). Single-threaded by design (refine.hpp).
// Run: build/bin/refine_bench [--benchmark_format=json]
#include "isohex/mesh/generate.hpp"
#include "isohex/mesh/refine.hpp"

#include <benchmark/benchmark.h>

#include <vector>

namespace {

using isohex::HexMesh;

constexpr int kCells = 60;

const HexMesh& grid() {
  static const HexMesh mesh = isohex::box_mesh(kCells, kCells, kCells);
  return mesh;
}

// Vertices within `radius` (a fraction of the box) of the centre; 1 = all of them.
std::vector<std::uint8_t> ball_marks(const HexMesh& m, double radius) {
  std::vector<std::uint8_t> marks(m.points.size(), 0);
  for (std::size_t v = 0; v < m.points.size(); ++v)
    marks[v] = (m.points[v] - isohex::Vec3::Constant(0.5)).norm() <= radius * 0.87;
  return marks;
}

void BM_Refine(benchmark::State& state) {
  const HexMesh& m = grid();
  const std::vector<std::uint8_t> marks = ball_marks(m, static_cast<double>(state.range(0)) / 100.0);
  std::size_t hexes = 0, promoted = 0;
  for (auto _ : state) {
    const isohex::RefineResult r = isohex::refine(m, marks);
    hexes = r.mesh.hexes.size();
    promoted = r.promoted_vertices;
    benchmark::DoNotOptimize(r.mesh.points.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(hexes));
  state.counters["hexes_in"] = static_cast<double>(m.hexes.size());
  state.counters["hexes_out"] = static_cast<double>(hexes);
  state.counters["promoted"] = static_cast<double>(promoted);
}
// A ball of a quarter of the box, and everything (radius 100 % of the half-diagonal).
BENCHMARK(BM_Refine)->Arg(25)->Arg(100)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
