// isohex generate box|ball -o OUT: meshes made from nothing, for trials and the default job.
#include "commands.hpp"

#include "isohex/error.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/generate.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <memory>
#include <vector>

namespace isohex::cli {

void register_generate(CLI::App& app) {
  struct Args {
    std::string shape, out;
    std::vector<int> resolution{16};
    std::vector<double> size{1.0};
    double jitter = 0.0;
    unsigned seed = 1;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("generate", "Generate a test mesh: a box grid or a mapped ball");
  cmd->add_option("shape", a->shape, "box (a structured grid) or ball (a cube grid mapped onto a sphere)")
      ->required()
      ->check(CLI::IsMember({"box", "ball"}));
  cmd->add_option("-o,--output", a->out, fmt::format("Output mesh ({})", io::kMeshExtensions))->required();
  cmd->add_option("-n,--resolution", a->resolution, "Cells along each axis (default 16); a box also takes NX NY NZ")
      ->expected(1, 3)
      ->check(CLI::Range(1, 2000));
  cmd->add_option("--size", a->size, "Edge length of the box (or LX LY LZ) / radius of the ball (default 1)")
      ->expected(1, 3)
      ->check(CLI::PositiveNumber);
  cmd->add_option("--jitter", a->jitter, "Random vertex displacement, as a fraction of the cell size (default 0)")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--seed", a->seed, "Random seed for --jitter");
  cmd->callback([a] {
    const bool box = a->shape == "box";
    for (const std::size_t n : {a->resolution.size(), a->size.size()})
      if (n == 2 || (n == 3 && !box)) throw Error("--resolution and --size take one value, or three for a box");
    const auto axis = [](const auto& v, int k) { return v[v.size() == 3 ? static_cast<std::size_t>(k) : 0]; };
    HexMesh m = box ? box_mesh(axis(a->resolution, 0), axis(a->resolution, 1), axis(a->resolution, 2), Vec3::Zero(),
                               Vec3(axis(a->size, 0), axis(a->size, 1), axis(a->size, 2)))
                    : ball_mesh(a->resolution[0], a->size[0]);
    double cell = 2 * a->size[0] / a->resolution[0];  // the ball's grid spans [-r, r]
    if (box) {
      cell = axis(a->size, 0) / axis(a->resolution, 0);
      for (int k = 1; k < 3; ++k) cell = std::min(cell, axis(a->size, k) / axis(a->resolution, k));
    }
    if (a->jitter > 0) jitter(m, a->jitter * cell, a->seed);
    io::write_mesh(a->out, m);
    fmt::print("wrote {}: {} hexes, {} vertices\n", a->out, m.num_hexes(), m.num_vertices());
  });
}

}  // namespace isohex::cli
