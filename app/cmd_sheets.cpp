// isohex sheets MESH: the dual sheets, their self-intersections and boundary capture (§3).
#include "commands.hpp"

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/mesh/validate.hpp"
#include "isohex/sheets/dual_sheets.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <memory>
#include <ostream>

namespace isohex::cli {

namespace {

struct Args {
  std::string mesh, json;
  bool skip_non_hex = false;
};

void run(const Args& a) {
  const HexMesh mesh = load_mesh(a.mesh, a.skip_non_hex);
  const ValidationReport v = validate(mesh, {.max_messages = 1});
  if (!v.topology_checked) throw Error(fmt::format("{}: vertex ids out of range; run 'isohex check'", a.mesh));
  const SheetReport r = extract_sheets(mesh);
  const auto [mn, mx] = std::minmax_element(r.sheet_sizes.begin(), r.sheet_sizes.end());

  fmt::print("{}: {} hexes, {} sheets (hexes per sheet: min {}, max {})\n", a.mesh, mesh.num_hexes(), r.num_sheets,
             r.sheet_sizes.empty() ? 0 : *mn, r.sheet_sizes.empty() ? 0 : *mx);
  fmt::print("self-intersecting sheets: {} ({} hexes where a sheet meets itself)\n", r.self_intersecting.size(),
             r.self_intersecting_hexes);
  std::size_t single = 0;
  for (std::size_t c = 0; c < r.boundary_capture.size(); ++c) {
    const auto& s = r.boundary_capture[c];
    single += s.size() == 1;
    if (s.size() <= 8)
      fmt::print("boundary component {} ({} quads): captured by {} sheet(s) [{}]\n", c, r.boundary_component_quads[c],
                 s.size(), fmt::join(s, ", "));
    else
      fmt::print("boundary component {} ({} quads): captured by {} sheets\n", c, r.boundary_component_quads[c],
                 s.size());
  }
  fmt::print("boundary components captured by a single sheet: {} of {}\n", single, r.boundary_capture.size());
  fmt::print("hexes with >= 2 boundary faces: {}\n", r.multi_boundary_hexes);

  if (!a.json.empty()) {
    nlohmann::json j;
    j["mesh"] = a.mesh;
    j["hexes"] = mesh.num_hexes();
    j["sheets"] = r.num_sheets;
    j["sheet_sizes"] = r.sheet_sizes;
    j["self_intersecting_sheets"] = r.self_intersecting;
    j["self_intersecting_hexes"] = r.self_intersecting_hexes;
    nlohmann::json comps = nlohmann::json::array();
    for (std::size_t c = 0; c < r.boundary_capture.size(); ++c)
      comps.push_back({{"quads", r.boundary_component_quads[c]}, {"sheets", r.boundary_capture[c]}});
    j["boundary_components"] = comps;
    j["components_captured_by_one_sheet"] = single;
    j["multi_boundary_hexes"] = r.multi_boundary_hexes;
    write_json(a.json, j);
  }
}

}  // namespace

void register_sheets(CLI::App& app) {
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("sheets", "Dual sheets: count, sizes, self-intersections, boundary capture");
  cmd->add_option("mesh", a->mesh, "Hex mesh (.vtk .vtu .mesh .inp)")->required();
  cmd->add_option("--json", a->json, "Write the sheet report as JSON");
  cmd->add_flag("--skip-non-hex", a->skip_non_hex, "Drop non-hexahedral cells instead of failing");
  cmd->callback([a] { run(*a); });
}

}  // namespace isohex::cli
