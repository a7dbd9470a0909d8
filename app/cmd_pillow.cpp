// isohex pillow IN -o OUT: insert a dual sheet around a shrink set (§4.1.1).
#include "commands.hpp"

#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/sheets/pillow.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <memory>
#include <ostream>

namespace isohex::cli {

namespace {

struct Args {
  std::string input, output, json, shrink_set = "boundary";
  double offset = PillowOptions{}.offset;
  bool skip_non_hex = false;
};

void run(const Args& a) {
  const HexMesh mesh = load_mesh(a.input, a.skip_non_hex);
  const std::vector<std::uint8_t> set = shrink_set_from_spec(mesh, a.shrink_set);
  PillowOptions opt;
  opt.offset = a.offset;
  opt.include_boundary = spec_includes_boundary(a.shrink_set);
  const std::size_t multi_before = count_multi_boundary_hexes(mesh);
  const PillowResult r = pillow(mesh, set, opt);
  const std::size_t multi_after = count_multi_boundary_hexes(r.mesh);
  const auto shrink_hexes = std::count_if(set.begin(), set.end(), [](std::uint8_t f) { return f != 0; });
  write_result(a.output, r.mesh);

  fmt::print("{}: {} hexes, {} vertices; shrink set '{}': {} hexes\n", a.input, mesh.num_hexes(), mesh.num_vertices(),
             a.shrink_set, shrink_hexes);
  fmt::print("interface: {} quads, {} vertices; pinch copies: {} ({} taken by outside hexes); pinched edges: {} "
             "({} with the shrink side merged); displacements reduced: {}\n",
             r.interface_quads, r.interface_vertices, r.pinch_copies, r.outside_copies, r.pinched_edges,
             r.flipped_edges, r.reduced_vertices);
  if (!r.added.empty() || !r.removed.empty())
    fmt::print("shrink set adjusted by +{}/-{} hexes (pinches with no valid placement)\n", r.added.size(),
               r.removed.size());
  if (r.folded_vertices > 0)
    fmt::print("warning: the interface is folded at {} vertices (e.g. inverted boundary quads): {} new hexes and {} "
               "changed hexes are inverted; untangle them (isohex smooth --untangle)\n",
               r.folded_vertices, r.inverted_new_hexes, r.inverted_changed_hexes);
  fmt::print("new hexes: {} (min scaled Jacobian {:.4f}); result: {} hexes, {} vertices\n", r.interface_quads,
             r.min_new_scaled_jacobian, r.mesh.num_hexes(), r.mesh.num_vertices());
  fmt::print("hexes with >= 2 boundary faces: {} before, {} after\n", multi_before, multi_after);
  fmt::print("wrote {}\n", a.output);

  if (!a.json.empty()) {
    nlohmann::json j;
    j["input"] = a.input;
    j["output"] = a.output;
    j["shrink_set"] = a.shrink_set;
    j["shrink_set_hexes"] = shrink_hexes;
    j["offset"] = a.offset;
    j["interface_quads"] = r.interface_quads;
    j["interface_vertices"] = r.interface_vertices;
    j["pinch_copies"] = r.pinch_copies;
    j["reduced_vertices"] = r.reduced_vertices;
    j["outside_copies"] = r.outside_copies;
    j["pinched_edges"] = r.pinched_edges;
    j["flipped_edges"] = r.flipped_edges;
    j["shrink_set_added"] = r.added.size();
    j["shrink_set_removed"] = r.removed.size();
    j["folded_vertices"] = r.folded_vertices;
    j["inverted_new_hexes"] = r.inverted_new_hexes;
    j["inverted_changed_hexes"] = r.inverted_changed_hexes;
    j["new_hexes"] = r.interface_quads;
    j["min_new_scaled_jacobian"] = r.min_new_scaled_jacobian;
    j["hexes_before"] = mesh.num_hexes();
    j["hexes_after"] = r.mesh.num_hexes();
    j["vertices_before"] = mesh.num_vertices();
    j["vertices_after"] = r.mesh.num_vertices();
    j["multi_boundary_hexes_before"] = multi_before;
    j["multi_boundary_hexes_after"] = multi_after;
    write_json(a.json, j);
  }
}

}  // namespace

void register_pillow(CLI::App& app) {
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("pillow", "Insert a dual sheet around a shrink set by pillowing");
  cmd->add_option("input", a->input, "Hex mesh (.vtk .vtu .mesh .inp)")->required();
  cmd->add_option("-o,--output", a->output, "Pillowed mesh (a .vtu / .vtk / .exo carries per hex scaled_jacobian and jacobian_ratio)")->required();
  cmd->add_option("--shrink-set", a->shrink_set,
                  "boundary (default: a sheet along every boundary component), block:ID, region:EXPR (hexes whose "
                  "centroid is inside the shape) or ids:FILE (one hex id per line)");
  cmd->add_option("--offset", a->offset, "Layer thickness / local edge length, in (0, 1) (default 0.25)");
  cmd->add_option("--json", a->json, "Write the counts as JSON");
  cmd->add_flag("--skip-non-hex", a->skip_non_hex, "Drop non-hexahedral cells instead of failing");
  cmd->callback([a] { run(*a); });
}

}  // namespace isohex::cli
