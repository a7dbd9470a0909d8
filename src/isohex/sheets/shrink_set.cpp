// Shrink sets from CLI specifications: boundary, block:ID, region:EXPR, ids:FILE.
#include "isohex/sheets/pillow.hpp"
#include "isohex/volume/hex_selection.hpp"

namespace isohex {

std::vector<std::uint8_t> shrink_set_from_spec(const HexMesh& mesh, const std::string& spec) {
  return select_hexes(mesh, spec, "shrink set", "boundary");
}

bool spec_includes_boundary(const std::string& spec) { return spec == "boundary" || spec.rfind("block:", 0) == 0; }

}  // namespace isohex
