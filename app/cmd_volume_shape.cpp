// isohex volume shape "EXPR" -o OUT: an implicit shape (primitives and CSG) sampled as a
// signed-distance volume.
#include "commands.hpp"

#include "isohex/error.hpp"
#include "isohex/volume/implicit.hpp"
#include "isohex/volume/volume_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <memory>

namespace isohex::cli {

namespace {

struct Args {
  std::string expression, output;
  std::vector<Index> dims;
  std::vector<double> bounds;
  double cell_size = 0, margin = 0.1;
  int* threads = nullptr;
};

constexpr const char* kGrammar =
    "Shape syntax (numbers are decimal; whitespace is free):\n"
    "  sphere(cx, cy, cz, r)\n"
    "  box(x0, y0, z0, x1, y1, z1)            corners, x0 < x1, y0 < y1, z0 < z1\n"
    "  cylinder(x0, y0, z0, x1, y1, z1, r)    capped, axis from (x0,y0,z0) to (x1,y1,z1)\n"
    "  torus(cx, cy, cz, R, r)                around the z axis, 0 < r < R\n"
    "  torus(cx, cy, cz, ax, ay, az, R, r)    around the axis (ax, ay, az)\n"
    "  plane(px, py, pz, nx, ny, nz)          half-space behind the plane, n pointing out\n"
    "  union(S, S, ...)   intersection(S, S, ...)   difference(S, S, ...) = the first minus the others\n"
    "e.g. \"difference(box(-1,-1,-1, 1,1,1), sphere(0,0,0, 1.2))\".\n"
    "Values are signed distances (exact for primitives, min/max for CSG), negative inside: the surface\n"
    "is the isovalue 0 with inside below it. Default bounds: the shape's bounding box grown by --margin.\n";

// Points of the grid's outer faces that are inside or on the shape (value <= 0).
std::size_t inside_on_boundary(const Volume& v) {
  std::size_t n = 0;
  const auto [nx, ny, nz] = v.dims;
  for (Index k = 0; k < nz; ++k)
    for (Index j = 0; j < ny; ++j)
      for (Index i = 0; i < nx; ++i)
        if (i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1) n += v.at(i, j, k) <= 0;
  return n;
}

void run(const Args& a) {
  ThreadLimit limit(*a.threads);
  require_volume_output(a.output);
  const auto start = std::chrono::steady_clock::now();
  const Shape shape = parse_shape(a.expression);
  Aabb box;
  if (!a.bounds.empty()) {
    box = {Vec3(a.bounds[0], a.bounds[1], a.bounds[2]), Vec3(a.bounds[3], a.bounds[4], a.bounds[5])};
  } else {
    try {
      box = sampling_bounds(shape, a.margin);
    } catch (const Error& e) {
      throw Error(fmt::format("{} (--bounds x0 y0 z0 x1 y1 z1)", e.what()));
    }
  }
  const SampleGrid grid =
      a.dims.empty() ? grid_from_cell_size(box, a.cell_size) : grid_from_dims(box, {a.dims[0], a.dims[1], a.dims[2]});
  const Volume v = sample(shape, grid);
  const double time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const auto [lo, hi] = std::minmax_element(v.values.begin(), v.values.end());
  const auto inside = std::count_if(v.values.begin(), v.values.end(), [](float x) { return x < 0; });
  const Vec3 far = v.max_corner();
  fmt::print("shape        {}\n", to_shape_string(shape));
  fmt::print("dims         {} x {} x {} ({} points)\n", v.dims[0], v.dims[1], v.dims[2], v.size());
  fmt::print("spacing      {:.6g} {:.6g} {:.6g}\n", v.spacing.x(), v.spacing.y(), v.spacing.z());
  fmt::print("bounds       ({:.6g}, {:.6g}, {:.6g}) to ({:.6g}, {:.6g}, {:.6g})\n", v.origin.x(), v.origin.y(),
             v.origin.z(), far.x(), far.y(), far.z());
  fmt::print("distance     {:.6g} to {:.6g}; {} points inside\n", *lo, *hi, inside);
  if (inside == 0) fmt::print("warning: no grid point is inside the shape\n");
  if (const std::size_t open = inside_on_boundary(v))
    fmt::print("warning: {} points on the grid's faces are inside the shape, so its surface is cut open there\n",
               open);
  write_volume(a.output, v);
  fmt::print("time         {:.3f} s\n", time);
  fmt::print("wrote {}; isovalue 0 (inside is below it)\n", a.output);
}

}  // namespace

void register_volume_shape(CLI::App& volume) {
  auto a = std::make_shared<Args>();
  CLI::App* cmd = volume.add_subcommand("shape", "Signed-distance volume of an implicit shape (primitives and CSG)");
  cmd->add_option("expression", a->expression, "The shape, e.g. \"union(sphere(0,0,0,1), torus(0,0,0, 2, 0.5))\"")
      ->required();
  cmd->add_option("-o,--output", a->output, "Output volume (.nrrd or .vti)")->required();
  CLI::Option* dims = cmd->add_option("--dims", a->dims, "Grid points along x, y, z, spanning the bounds exactly")
                          ->expected(3)
                          ->check(CLI::Range(2, 1 << 20));
  CLI::Option* cell = cmd->add_option("--cell-size", a->cell_size, "Distance between grid points (grid centred on the bounds)")
                          ->check(CLI::PositiveNumber);
  dims->excludes(cell);
  cmd->add_option("--bounds", a->bounds, "Region to sample: x0 y0 z0 x1 y1 z1 (default: the shape's box plus the margin)")
      ->expected(6);
  cmd->add_option("--margin", a->margin, "Default bounds: grow the shape's box by this fraction of its largest side "
                                         "on every side (default 0.1)")
      ->check(CLI::NonNegativeNumber);
  a->threads = add_threads_option(cmd);
  cmd->footer(kGrammar);
  cmd->callback([a, dims, cell] {
    if (dims->count() == 0 && cell->count() == 0) throw Error("give the grid: --dims NX NY NZ or --cell-size H");
    run(*a);
  });
}

}  // namespace isohex::cli
