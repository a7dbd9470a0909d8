// The optimisation sequence shared by `isohex smooth` and `isohex mesh`.
#include "isohex/optimize/optimize.hpp"

#include <chrono>

namespace isohex {

OptimizeResult optimize_mesh(HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const OptimizeOptions& options) {
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  OptimizeResult r;
  auto t = Clock::now();
  UntangleOptions u = options.untangle_options;
  ShapeOptions s = options.shape_options;
  WorstOptions w = options.worst_options;
  Incidence own;
  for (const Incidence** inc : {&u.incidence, &s.incidence, &w.incidence})
    if (!*inc) {
      if (own.offsets.empty()) own = vertex_hexes(mesh);
      *inc = &own;
    }
  if (options.untangle) {
    r.untangled = true;
    r.untangle = untangle(mesh, fixed, u);
    r.untangle_seconds = since(t);
  }
  t = Clock::now();
  r.shape = optimize_shape(mesh, fixed, s);
  r.shape_seconds = since(t);
  if (options.worst) {
    t = Clock::now();
    r.worst_run = true;
    r.worst = improve_worst(mesh, fixed, w);
    r.worst_seconds = since(t);
  }
  return r;
}

}  // namespace isohex
