// isohex generate box|ball -o OUT: meshes made from nothing, for trials and the default job.
#include "commands.hpp"

#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/generate.hpp"

#include <fmt/format.h>

#include <memory>

namespace isohex::cli {

void register_generate(CLI::App& app) {
  struct Args {
    std::string shape, out;
    int resolution = 16;
    double size = 1.0, jitter = 0.0;
    unsigned seed = 1;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("generate", "Generate a test mesh: a box grid or a mapped ball");
  cmd->add_option("shape", a->shape, "box (a structured grid) or ball (a cube grid mapped onto a sphere)")
      ->required()
      ->check(CLI::IsMember({"box", "ball"}));
  cmd->add_option("-o,--output", a->out, fmt::format("Output mesh ({})", io::kMeshExtensions))->required();
  cmd->add_option("-n,--resolution", a->resolution, "Cells along each axis (default 16)")->check(CLI::Range(1, 2000));
  cmd->add_option("--size", a->size, "Edge length of the box / radius of the ball (default 1)")->check(CLI::PositiveNumber);
  cmd->add_option("--jitter", a->jitter, "Random vertex displacement, as a fraction of the cell size (default 0)")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--seed", a->seed, "Random seed for --jitter");
  cmd->callback([a] {
    HexMesh m = a->shape == "box" ? box_mesh(a->resolution, a->resolution, a->resolution, Vec3::Zero(),
                                             Vec3::Constant(a->size))
                                  : ball_mesh(a->resolution, a->size);
    const double cell = (a->shape == "box" ? a->size : 2 * a->size) / a->resolution;
    if (a->jitter > 0) jitter(m, a->jitter * cell, a->seed);
    io::write_mesh(a->out, m);
    fmt::print("wrote {}: {} hexes, {} vertices\n", a->out, m.num_hexes(), m.num_vertices());
  });
}

}  // namespace isohex::cli
