// isohex refine IN -o OUT: conforming local 3-refinement by transition templates.
#include "commands.hpp"

#include "isohex/error.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/refine.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/volume/hex_selection.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <limits>
#include <memory>

namespace isohex::cli {

namespace {

struct Args {
  std::string input, output, json, hexes = "all";
  bool skip_non_hex = false;
};

/// Minimum scaled Jacobian, degenerate elements left out (as in isohex quality).
double min_scaled_jacobian(const HexMesh& mesh) {
  double m = std::numeric_limits<double>::infinity();
  for (double v : scaled_jacobians(mesh))
    if (!is_degenerate(v)) m = std::min(m, v);
  return m;
}

void run(const Args& a) {
  const HexMesh mesh = load_mesh(a.input, a.skip_non_hex);
  const std::vector<std::uint8_t> set = select_hexes(mesh, a.hexes, "--hexes");
  std::vector<Index> ids;
  for (Index h = 0; h < mesh.num_hexes(); ++h)
    if (set[h]) ids.push_back(h);
  if (ids.empty()) throw Error(fmt::format("--hexes '{}': the selection is empty ({} hexes in {})", a.hexes,
                                           mesh.num_hexes(), a.input));
  const RefineResult r = refine(mesh, marked_vertices_of(mesh, ids));
  const double sj_before = min_scaled_jacobian(mesh), sj_after = min_scaled_jacobian(r.mesh);
  write_result(a.output, r.mesh);

  fmt::print("{}: {} hexes, {} vertices; selection '{}': {} hexes\n", a.input, mesh.num_hexes(), mesh.num_vertices(),
             a.hexes, ids.size());
  fmt::print("marked vertices: {}; promoted: {}\n", r.marked_vertices, r.promoted_vertices);
  fmt::print("templates (parent hexes -> new hexes):\n");
  for (int t = 0; t < kNumRefineTemplates; ++t)
    fmt::print("  {:<10} {:>8} -> {:>8}\n", refine_template_name(static_cast<RefineTemplate>(t)), r.parents[t],
               r.children[t]);
  fmt::print("result: {} hexes, {} vertices\n", r.mesh.num_hexes(), r.mesh.num_vertices());
  fmt::print("min scaled Jacobian: {:.4f} before, {:.4f} after\n", sj_before, sj_after);
  fmt::print("wrote {}\n", a.output);

  if (!a.json.empty()) {
    nlohmann::json j;
    j["input"] = a.input;
    j["output"] = a.output;
    j["selection"] = a.hexes;
    j["selected_hexes"] = ids.size();
    j["marked_vertices"] = r.marked_vertices;
    j["promoted_vertices"] = r.promoted_vertices;
    for (int t = 0; t < kNumRefineTemplates; ++t) {
      const char* name = refine_template_name(static_cast<RefineTemplate>(t));
      j["templates"][name] = {{"parents", r.parents[t]}, {"hexes", r.children[t]}};
    }
    j["hexes_before"] = mesh.num_hexes();
    j["hexes_after"] = r.mesh.num_hexes();
    j["vertices_before"] = mesh.num_vertices();
    j["vertices_after"] = r.mesh.num_vertices();
    j["min_scaled_jacobian_before"] = sj_before;
    j["min_scaled_jacobian_after"] = sj_after;
    write_json(a.json, j);
  }
}

}  // namespace

void register_refine(CLI::App& app) {
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("refine", "Refine hexes locally, conformingly, by 3-refinement templates");
  cmd->add_option("input", a->input, "Hex mesh (.vtk .vtu .mesh .inp .exo .msh)")->required();
  cmd->add_option("-o,--output", a->output, "Refined mesh (a .vtu / .vtk / .exo carries per hex scaled_jacobian and jacobian_ratio)")->required();
  cmd->add_option("--hexes", a->hexes,
                  "Hexes to refine: all (default), block:ID, region:EXPR (hexes whose centroid is inside the shape, "
                  "syntax of 'isohex volume shape') or ids:FILE (one hex id per line); their 8 vertices are marked");
  cmd->add_option("--json", a->json, "Write the counts as JSON");
  cmd->add_flag("--skip-non-hex", a->skip_non_hex, "Drop non-hexahedral cells instead of failing");
  cmd->callback([a] { run(*a); });
}

}  // namespace isohex::cli
