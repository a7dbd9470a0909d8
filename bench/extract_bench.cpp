// Extraction throughput of the dual-contouring hex mesher: cthead (256 x 256 x 113, spacing
// 1 1 2 assumed) at h = 1 voxel, skin isovalue 600. Reports hexes/s and the peak resident
// memory (getrusage), to check the ≥ 1 M hexes/s target and memory linear in the hexes.
#include "isohex/contour/dual_contour.hpp"
#include "isohex/volume/volume_io.hpp"

#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <cstdlib>
#include <filesystem>

namespace {

using namespace isohex;

const Volume* cthead() {
  static const Volume* v = [] {
    // The shared data folder: $ISOHEX_SHARED_DATA, else ../shared/data beside the checkout.
    const char* env = std::getenv("ISOHEX_SHARED_DATA");
    const std::filesystem::path data = env ? env : "/work/shared/data";
    const std::filesystem::path file = data / "volumes/cthead_256x256x113_int16be.raw";
    if (!std::filesystem::exists(file)) return static_cast<Volume*>(nullptr);
    VolumeReadOptions opt;
    RawLayout raw;
    raw.dims = {256, 256, 113};
    raw.type = ScalarType::i16;
    raw.big_endian = true;
    raw.spacing = Vec3(1, 1, 2);
    opt.raw = raw;
    return new Volume(read_volume(file, opt));
  }();
  return v;
}

void BM_ExtractCthead(benchmark::State& state) {
  const Volume* v = cthead();
  if (!v) {
    state.SkipWithError("cthead volume not found");
    return;
  }
  contour::RegionSpec spec;
  spec.isovalue = static_cast<double>(state.range(1));
  const contour::Region region = contour::make_region(*v, spec);
  contour::ExtractOptions opt;
  opt.cell_size = static_cast<double>(state.range(0));
  std::size_t hexes = 0;
  for (auto _ : state) {
    const contour::ExtractResult r = contour::extract_hex_mesh(region, opt);
    hexes = r.mesh.hexes.size();
    benchmark::DoNotOptimize(r.mesh.points.data());
  }
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  state.counters["hexes"] = static_cast<double>(hexes);
  state.counters["hexes_per_s"] = benchmark::Counter(static_cast<double>(hexes), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["maxrss_MiB"] = static_cast<double>(ru.ru_maxrss) / 1024.0;
}
// h = 1 (the brief's case: z resampled from spacing 2) and h = 2; skin (600) and bone (1500).
BENCHMARK(BM_ExtractCthead)->Args({1, 600})->Args({1, 1500})->Args({2, 600})->Unit(benchmark::kMillisecond)->Iterations(2)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
