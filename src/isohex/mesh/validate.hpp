#pragma once
/// \file validate.hpp
/// \brief Checks that a HexMesh is a valid, conformal hex mesh with a manifold boundary.
///
/// Each fault names the element and what is wrong, e.g. "hex 12: vertex id 900 at corner 3
/// is out of range [0, 640)". Errors make the mesh unusable for a solver; warnings (unused
/// vertices) do not.

#include "isohex/mesh/hex_mesh.hpp"

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace isohex {

/// The kinds of fault validate() finds.
enum class FaultKind {
  non_finite_coordinate,  ///< NaN or Inf in a vertex coordinate
  id_out_of_range,        ///< a hex names a vertex that does not exist
  repeated_vertex,        ///< a hex uses the same vertex at two corners
  quad_shared_by_many,    ///< a quad used by more than two hexes
  inconsistent_orientation,  ///< two hexes traverse their shared quad the same way (one is mirrored)
  non_manifold_edge,      ///< a boundary edge used by other than two boundary quads
  non_manifold_vertex,    ///< the boundary around a vertex is not a single disk
  unused_vertex,          ///< a vertex no hex uses (warning)
};

/// Short, stable name of a fault kind (used in JSON).
const char* fault_kind_name(FaultKind k);
/// True for kinds that make a mesh invalid (all except unused_vertex).
bool is_error(FaultKind k);

/// One fault with its message.
struct Fault {
  FaultKind kind;
  Index element;        ///< the hex, quad or vertex the message names (-1 if none)
  std::string message;
};

/// The result of validate(): faults (at most `max_messages` kept per kind, all counted)
/// and boundary statistics.
struct ValidationReport {
  std::vector<Fault> faults;
  std::map<FaultKind, std::size_t> counts;
  std::size_t num_quads = 0;            ///< unique quads
  std::size_t num_boundary_quads = 0;
  std::size_t num_boundary_vertices = 0;
  std::size_t num_boundary_edges = 0;
  std::size_t num_boundary_components = 0;  ///< connected components of the boundary surface
  long euler_characteristic = 0;        ///< V - E + F of the boundary surface
  bool topology_checked = false;        ///< false when ids out of range prevented the topology checks

  [[nodiscard]] std::size_t count(FaultKind k) const {
    auto it = counts.find(k);
    return it == counts.end() ? 0 : it->second;
  }
  [[nodiscard]] std::size_t num_errors() const;
  [[nodiscard]] std::size_t num_warnings() const;
  [[nodiscard]] bool valid() const { return num_errors() == 0; }
};

struct ValidateOptions {
  std::size_t max_messages = 20;  ///< messages kept per fault kind
};

/// Validates `mesh`. Never throws on a bad mesh: everything is in the report.
ValidationReport validate(const HexMesh& mesh, const ValidateOptions& options = {});

}  // namespace isohex
