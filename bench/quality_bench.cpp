// Scaled-Jacobian throughput (items/s = hexes/s) on a 1,000,000-hex perturbed grid.
//
// The mesh is `isohex generate box -n 100 --jitter 0.3` built in memory (same generator, same
// seed), so bench/quality_vs_vtk.py can hand VTK the very same mesh; the min_sj counter lets
// it check that. Run: build/bin/quality_bench [--benchmark_format=json]
#include "isohex/mesh/generate.hpp"
#include "isohex/quality/hex_quality.hpp"

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <vector>

namespace {

using isohex::HexMesh;

constexpr int kCells = 100;       // 100^3 hexes
constexpr double kJitter = 0.3;   // vertex displacement, fraction of the cell size

const HexMesh& grid() {
  static const HexMesh mesh = [] {
    HexMesh m = isohex::box_mesh(kCells, kCells, kCells);
    isohex::jitter(m, kJitter / kCells, 1);
    return m;
  }();
  return mesh;
}

double min_value(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

/// The whole-mesh fast path, on range(0) threads.
void BM_ScaledJacobians(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  const HexMesh& m = grid();
  std::vector<double> sj;
  for (auto _ : state) {
    sj = isohex::scaled_jacobians(m);
    benchmark::DoNotOptimize(sj.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(m.hexes.size()));
  state.counters["tbb_threads"] = threads;
  state.counters["hexes"] = static_cast<double>(m.hexes.size());
  state.counters["min_sj"] = min_value(sj);
}
BENCHMARK(BM_ScaledJacobians)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The per-element function in a plain loop (one thread): what the fast path is measured against.
void BM_ScaledJacobianPerElement(benchmark::State& state) {
  const HexMesh& m = grid();
  std::vector<double> sj(m.hexes.size());
  for (auto _ : state) {
    for (isohex::Index h = 0; h < m.num_hexes(); ++h)
      sj[static_cast<std::size_t>(h)] = isohex::scaled_jacobian(m.corners(h));
    benchmark::DoNotOptimize(sj.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(m.hexes.size()));
  state.counters["min_sj"] = min_value(sj);
}
BENCHMARK(BM_ScaledJacobianPerElement)->Unit(benchmark::kMillisecond)->UseRealTime();

/// Another metric through the generic parallel path, for scale (2 threads).
void BM_MeanRatio(benchmark::State& state) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
  const HexMesh& m = grid();
  std::vector<double> v;
  for (auto _ : state) {
    v = isohex::hex_metric(m, isohex::HexMetric::mean_ratio);
    benchmark::DoNotOptimize(v.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(m.hexes.size()));
}
BENCHMARK(BM_MeanRatio)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
