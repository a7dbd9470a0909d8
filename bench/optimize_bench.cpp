// Throughput of the shape optimiser and the untangler on a 512,000-hex grid (80³).
//
// hex_iter/s = hexes × Gauss–Seidel sweeps per second of wall time, set-up included (incidence,
// colouring, edge lengths, the infeasibility proofs). A shape sweep is one Newton step per
// free vertex; an untangler outer iteration is UntangleOptions::sweeps (default 1) sweeps of 2
// Newton steps each, counted as that many sweeps (it moves only vertices within 3 rings of hexes
// below the margin, here nearly all).
// Run: build/bin/optimize_bench [--benchmark_format=json]
#include "isohex/mesh/generate.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/quality/hex_quality.hpp"

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <vector>

namespace {

using isohex::HexMesh;

constexpr int kCells = 80;  // 80^3 = 512,000 hexes

// jitter: vertex displacement as a fraction of the cell size, boundary vertices held.
HexMesh grid(double jitter, unsigned seed) {
  HexMesh m = isohex::box_mesh(kCells, kCells, kCells);
  m.fixed = isohex::boundary_vertex_mask(m);
  isohex::jitter(m, jitter / kCells, seed);
  return m;
}

std::size_t inverted(const HexMesh& m) {
  std::size_t n = 0;
  for (double q : isohex::scaled_jacobians(m)) n += q <= 0 || isohex::is_degenerate(q);
  return n;
}

/// Five shape sweeps (no early stop) from a valid 0.3-jittered grid, on range(0) threads.
void BM_ShapeSweeps(benchmark::State& state) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
  static const HexMesh start = grid(0.3, 1);
  isohex::ShapeOptions o;
  o.max_iter = 5;
  o.tol = 0;
  o.grad_tol = 0;
  double sweeps = 0, before = 0, after = 0;
  for (auto _ : state) {
    state.PauseTiming();
    HexMesh m = start;
    state.ResumeTiming();
    const isohex::ShapeResult r = isohex::optimize_shape(m, m.fixed, o);
    sweeps += r.iterations;
    before = r.objective_before;
    after = r.objective_after;
  }
  state.counters["hexes"] = static_cast<double>(start.hexes.size());
  state.counters["hex_iter/s"] =
      benchmark::Counter(sweeps * static_cast<double>(start.hexes.size()), benchmark::Counter::kIsRate);
  state.counters["objective_before"] = before;
  state.counters["objective_after"] = after;
  state.counters["tbb_threads"] = static_cast<double>(state.range(0));
}
BENCHMARK(BM_ShapeSweeps)->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

/// Untangling a 0.5-jittered grid (inverted hexes everywhere) to the default 0.05 margin, on
/// range(0) threads.
void BM_Untangle(benchmark::State& state) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
  static const HexMesh start = grid(0.5, 2);
  static const std::size_t tangled = inverted(start);
  double iters = 0, left = 0, min_sj = 0;
  for (auto _ : state) {
    state.PauseTiming();
    HexMesh m = start;
    state.ResumeTiming();
    const isohex::UntangleResult r = isohex::untangle(m, m.fixed);
    iters += r.iterations * isohex::UntangleOptions{}.sweeps;
    left = static_cast<double>(r.inverted);
    min_sj = r.min_sj;
  }
  state.counters["hexes"] = static_cast<double>(start.hexes.size());
  state.counters["inverted_before"] = static_cast<double>(tangled);
  state.counters["inverted_after"] = left;
  state.counters["min_sj_after"] = min_sj;
  state.counters["sweeps"] = iters / static_cast<double>(state.iterations());
  state.counters["hex_iter/s"] =
      benchmark::Counter(iters * static_cast<double>(start.hexes.size()), benchmark::Counter::kIsRate);
  state.counters["tbb_threads"] = static_cast<double>(state.range(0));
}
BENCHMARK(BM_Untangle)->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
