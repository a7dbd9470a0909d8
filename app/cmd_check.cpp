// isohex check MESH: validation report; exits 1 on an invalid mesh.
#include "commands.hpp"

#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/validate.hpp"
#include "isohex/quality/hex_quality.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <memory>
#include <ostream>

namespace isohex::cli {

namespace {

struct Args {
  std::string mesh, json;
  std::size_t max_messages = 20;
  bool strict = false, skip_non_hex = false;
};

void run(const Args& a) {
  const HexMesh mesh = load_mesh(a.mesh, a.skip_non_hex);
  ValidateOptions opt;
  opt.max_messages = a.max_messages;
  const ValidationReport r = validate(mesh, opt);

  // Inverted elements make a mesh unusable for a solver although it is topologically valid.
  std::size_t inverted = 0, degenerate = 0;
  if (r.topology_checked && r.count(FaultKind::non_finite_coordinate) == 0) {
    for (double v : scaled_jacobians(mesh)) {
      if (is_degenerate(v)) ++degenerate;
      else if (v < 0) ++inverted;
    }
  }

  fmt::print("{}: {} hexes, {} vertices\n", a.mesh, mesh.num_hexes(), mesh.num_vertices());
  for (const Fault& f : r.faults) fmt::print("  {}: {}\n", is_error(f.kind) ? "error" : "warning", f.message);
  for (auto [k, c] : r.counts)
    if (c > a.max_messages) fmt::print("  ... {} {} faults in all\n", c, fault_kind_name(k));
  if (r.topology_checked)
    fmt::print("boundary: {} quads, {} edges, {} vertices, {} components, Euler characteristic {}\n",
               r.num_boundary_quads, r.num_boundary_edges, r.num_boundary_vertices, r.num_boundary_components,
               r.euler_characteristic);
  fmt::print("inverted hexes (scaled Jacobian < 0): {}, degenerate: {}\n", inverted, degenerate);
  const bool ok = r.valid() && (!a.strict || r.num_warnings() == 0);
  fmt::print("{}: {} errors, {} warnings\n", ok ? "VALID" : "INVALID", r.num_errors(), r.num_warnings());

  if (!a.json.empty()) {
    nlohmann::json j;
    j["mesh"] = a.mesh;
    j["valid"] = ok;
    j["hexes"] = mesh.num_hexes();
    j["vertices"] = mesh.num_vertices();
    j["errors"] = r.num_errors();
    j["warnings"] = r.num_warnings();
    j["inverted"] = inverted;
    j["degenerate"] = degenerate;
    nlohmann::json counts = nlohmann::json::object();
    for (auto [k, c] : r.counts) counts[fault_kind_name(k)] = c;
    j["fault_counts"] = counts;
    nlohmann::json faults = nlohmann::json::array();
    for (const Fault& f : r.faults)
      faults.push_back({{"kind", fault_kind_name(f.kind)}, {"element", f.element}, {"message", f.message}});
    j["faults"] = faults;
    if (r.topology_checked)
      j["boundary"] = {{"quads", r.num_boundary_quads},
                       {"edges", r.num_boundary_edges},
                       {"vertices", r.num_boundary_vertices},
                       {"components", r.num_boundary_components},
                       {"euler_characteristic", r.euler_characteristic}};
    write_json(a.json, j);
  }
  if (!ok) exit_code() = 1;
}

}  // namespace

void register_check(CLI::App& app) {
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("check", "Validate a hex mesh: ids, conformity, orientation, manifold boundary");
  cmd->add_option("mesh", a->mesh, fmt::format("Hex mesh ({})", io::kMeshExtensions))->required();
  cmd->add_option("--json", a->json, "Write the validation report as JSON");
  cmd->add_option("--max-messages", a->max_messages, "Messages shown per fault kind (default 20)");
  cmd->add_flag("--strict", a->strict, "Treat warnings (unused vertices) as errors");
  cmd->add_flag("--skip-non-hex", a->skip_non_hex, "Drop non-hexahedral cells instead of failing");
  cmd->callback([a] { run(*a); });
}

}  // namespace isohex::cli
