// isohex convert IN OUT: mesh format conversion by file extension.
#include "commands.hpp"

#include "isohex/io/mesh_io.hpp"

#include <fmt/format.h>

#include <memory>
#include <string>

namespace isohex::cli {

void register_convert(CLI::App& app) {
  struct Args {
    std::string in, out;
    bool skip_non_hex = false, ascii = false, no_compress = false, msh_binary = false, quality_fields = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("convert", fmt::format("Convert a hex mesh between formats (chosen by extension: {})", io::kMeshExtensions));
  cmd->add_option("input", args->in, "Input mesh")->required();
  cmd->add_option("output", args->out, "Output mesh")->required();
  cmd->add_flag("--skip-non-hex", args->skip_non_hex, "Drop non-hexahedral cells (and report how many) instead of failing");
  cmd->add_flag("--ascii", args->ascii, "Write .vtk/.vtu as ASCII (17 significant digits) instead of binary");
  cmd->add_flag("--no-compress", args->no_compress, "Write .vtu appended data without zlib compression");
  cmd->add_flag("--msh-binary", args->msh_binary, "Write .msh (Gmsh 4.1) in binary instead of ASCII");
  cmd->add_flag("--quality-fields", args->quality_fields,
                "Write .vtk/.vtu with each hex's scaled Jacobian and jacobian ratio as cell arrays (as isohex mesh, "
                "cut, pillow, refine and smooth always do)");
  cmd->footer("Examples:\n"
              "  isohex convert head.inp head.vtu --quality-fields   # open in ParaView, colour by scaled_jacobian\n"
              "  isohex convert head.vtu head.exo");
  cmd->callback([args] {
    io::ReadOptions ropt;
    ropt.skip_non_hex = args->skip_non_hex;
    io::ReadReport report;
    const HexMesh mesh = io::read_mesh(args->in, ropt, &report);
    if (report.skipped_cells) fmt::print("skipped {} non-hexahedral cells\n", report.skipped_cells);
    io::WriteOptions wopt;
    wopt.binary = !args->ascii;
    wopt.compress = !args->no_compress;
    wopt.msh_binary = args->msh_binary;
    if (args->quality_fields) wopt.cell_fields = io::quality_fields(mesh);
    io::write_mesh(args->out, mesh, wopt);
    fmt::print("wrote {}: {} hexes, {} vertices\n", args->out, mesh.num_hexes(), mesh.num_vertices());
  });
}

}  // namespace isohex::cli
