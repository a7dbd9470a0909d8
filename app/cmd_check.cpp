// isohex check MESH: validation report; exits 1 on an invalid mesh.
#include "commands.hpp"

#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/validate.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"
#include "isohex/quality/summary.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <memory>
#include <ostream>

namespace isohex::cli {

namespace {

struct Args {
  std::string mesh, json;
  std::size_t max_messages = 20;
  bool strict = false, skip_non_hex = false, topology = false;
  double short_edge = 1e-3;     // fraction of the median edge length
  double overlap_tol = 1e-3;    // relative volume excess
};

// What a solver integrating over the element sees: certified validity inside, the volume
// balance, and edges far below the mesh's size.
struct Inside {
  ValiditySummary validity;
  std::vector<JacobianBounds> invalid_bounds;  // of validity.invalid
  VolumeBalance volume;
  std::size_t short_edges = 0;
  double median_edge = 0, shortest_edge = 0;
};

Inside check_inside(const HexMesh& mesh, const Args& a) {
  Inside r;
  r.validity = summarize_validity(mesh, a.max_messages);
  for (Index h : r.validity.invalid) r.invalid_bounds.push_back(jacobian_bounds(mesh.corners(h)));
  r.volume = volume_balance(mesh);
  const auto edges = build_edges(mesh);
  std::vector<double> len(edges.size());
  for (std::size_t e = 0; e < edges.size(); ++e) len[e] = (mesh.points[edges[e][0]] - mesh.points[edges[e][1]]).norm();
  if (!len.empty()) {
    std::vector<double> sorted = len;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    r.median_edge = sorted[sorted.size() / 2];
    r.shortest_edge = *std::min_element(len.begin(), len.end());
    for (double l : len) r.short_edges += l < a.short_edge * r.median_edge;
  }
  return r;
}

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
  const bool geometry = !a.topology && r.topology_checked && r.count(FaultKind::non_finite_coordinate) == 0;
  Inside in;
  std::size_t errors = r.num_errors(), warnings = r.num_warnings();
  bool overlap = false;
  if (geometry) {
    in = check_inside(mesh, a);
    const ValiditySummary& v = in.validity;
    for (std::size_t i = 0; i < in.invalid_bounds.size(); ++i) {
      const JacobianBounds& b = in.invalid_bounds[i];
      fmt::print("  error: hex {}: not valid inside: min det J in [{:.6g}, {:.6g}] (certified), max det J {:.6g}\n",
                 v.invalid[i], b.min_lower, b.min_upper, b.max_upper);
    }
    if (v.not_valid_inside > v.invalid.size()) fmt::print("  ... {} hexes not valid inside in all\n", v.not_valid_inside);
    overlap = in.volume.excess() > a.overlap_tol;
    fmt::print("{}\n", describe(v));
    fmt::print("volume: hexes {:.9g} (|det J| integrated), boundary encloses {:.9g}: excess {:.3g}{}\n",
               in.volume.hexes, in.volume.enclosed, in.volume.excess(),
               overlap ? fmt::format(" > {:g}: elements overlap (error)", a.overlap_tol) : std::string());
    fmt::print("edges: median {:.6g}, shortest {:.6g}; {} below {:g} x median{}\n", in.median_edge,
               in.shortest_edge, in.short_edges, a.short_edge, in.short_edges ? " (warning)" : "");
    errors += in.validity.not_valid_inside + (overlap ? 1 : 0);
    warnings += in.short_edges;
  }
  const bool ok = errors == 0 && (!a.strict || warnings == 0);
  fmt::print("{}: {} errors, {} warnings\n", ok ? "VALID" : "INVALID", errors, warnings);

  if (!a.json.empty()) {
    nlohmann::json j;
    j["mesh"] = a.mesh;
    j["valid"] = ok;
    j["hexes"] = mesh.num_hexes();
    j["vertices"] = mesh.num_vertices();
    j["errors"] = errors;
    j["warnings"] = warnings;
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
    if (geometry) {
      j["validity"] = to_json(in.validity);
      j["not_valid_inside"] = in.validity.not_valid_inside;
      j["not_valid_inside_hexes"] = in.validity.invalid;
      j["gauss_nonpositive"] = in.validity.gauss_nonpositive;
      j["volume"] = {{"hexes", in.volume.hexes}, {"signed_hexes", in.volume.signed_hexes},
                     {"enclosed", in.volume.enclosed}, {"excess", in.volume.excess()}, {"overlap", overlap}};
      j["edges"] = {{"median", in.median_edge}, {"shortest", in.shortest_edge}, {"short", in.short_edges},
                    {"short_fraction", a.short_edge}};
    }
    write_json(a.json, j);
  }
  if (!ok) exit_code() = 1;
}

}  // namespace

void register_check(CLI::App& app) {
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "check", "Validate a hex mesh: ids, conformity, orientation, manifold boundary, every element valid inside");
  cmd->add_option("mesh", a->mesh, fmt::format("Hex mesh ({})", io::kMeshExtensions))->required();
  cmd->add_option("--json", a->json, "Write the validation report as JSON");
  cmd->add_option("--max-messages", a->max_messages, "Messages shown per fault kind (default 20)");
  cmd->add_flag("--strict", a->strict, "Treat warnings (unused vertices) as errors");
  cmd->add_flag("--skip-non-hex", a->skip_non_hex, "Drop non-hexahedral cells instead of failing");
  cmd->add_flag("--topology", a->topology,
                "Check ids, conformity, orientation and the boundary only, not the elements' validity inside (a raw "
                "extraction that an untangler will repair)");
  cmd->add_option("--short-edge", a->short_edge, "Warn about edges shorter than F x the median edge (default 1e-3)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--overlap-tolerance", a->overlap_tol,
                  "Error when the hexes' |det J| volume exceeds the enclosed volume by more than F (default 1e-3)")
      ->check(CLI::NonNegativeNumber);
  cmd->footer(
      "A hex is valid inside when det J > 0 everywhere in it, certified by the Bernstein coefficients of det J\n"
      "(subdivided where needed); Verdict's 9 samples are not enough. Exit 1 when any hex is not.\n"
      "Example: isohex check head.vtu --json head-check.json");
  cmd->callback([a] { run(*a); });
}

}  // namespace isohex::cli
