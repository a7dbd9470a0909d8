#pragma once
// Checks shared by the pillowing and sheet tests (defined in sheets_pillow_test.cpp).
#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/sheets/pillow.hpp"

#include <cstdint>
#include <vector>

namespace isohex::test {

/// Pillows and checks everything pillow() promises: counts, validity, no inverted new hex,
/// no newly inverted shrink-set hex, old ids kept, copies' originals. Returns the result.
PillowResult checked_pillow(const HexMesh& mesh, const std::vector<std::uint8_t>& set, const PillowOptions& opt = {});

/// True if the boundary quads (as vertex tuples, up to order) and the coordinates of their
/// vertices are bit-identical in `a` and `b`.
bool same_surface(const HexMesh& a, const HexMesh& b);

}  // namespace isohex::test
