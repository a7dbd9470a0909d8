#pragma once
/// \file solver_sets.hpp
/// \brief What the solver formats (Exodus II, Gmsh, Abaqus) write besides nodes and hexes:
/// element blocks with positive ids, the boundary faces as (hex, face) pairs, the boundary
/// nodes, and each format's own face numbering.

#include "isohex/mesh/hex_mesh.hpp"

#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace isohex::io {

/// The distinct block values of a mesh and the positive ids the solver formats give them.
/// Those formats need ids >= 1, so the values themselves are used when they all are, and
/// 1, 2, ... in ascending value order otherwise; the value is kept in the name
/// (block_name) so that readers restore it exactly.
struct BlockTable {
  std::vector<Index> values;    ///< distinct block values, ascending (one 0 when the mesh has no blocks)
  std::vector<Index> file_ids;  ///< positive id per value
  std::vector<Index> of_hex;    ///< position in `values` of each hex's block
};
BlockTable block_table(const HexMesh& mesh);

/// "block_<value>", the name written for a block.
std::string block_name(Index value);
/// The value in a name written by block_name; false for any other name.
bool parse_block_name(std::string_view name, Index& value);

/// Blocks per hex from the names of the sets the hexes came from: the values in the names
/// when every name is a block_name, the file ids otherwise; empty when all of them are 0
/// (a mesh written without blocks). `set_of_hex` indexes `names` and `file_ids`.
std::vector<Index> blocks_from_sets(const std::vector<std::string>& names, const std::vector<Index>& file_ids,
                                    const std::vector<Index>& set_of_hex);

/// One boundary quad as the hex that owns it and its face number in kHexFaces (VTK order).
struct BoundaryFace {
  Index hex;
  int face;
};
/// The boundary quads of the mesh, in the deterministic order of build_quads.
std::vector<BoundaryFace> boundary_faces(const HexMesh& mesh);

/// The vertices on the boundary, ascending.
std::vector<Index> boundary_nodes(const HexMesh& mesh);

/// Exodus II side number (1..6) of each VTK face: Exodus' HEX8 sides are 1:(1,2,6,5)
/// 2:(2,3,7,6) 3:(3,4,8,7) 4:(1,5,8,4) 5:(1,4,3,2) 6:(5,6,7,8) in 1-based node numbers.
inline constexpr std::array<int, 6> kExodusSideOfVtkFace = {4, 2, 1, 3, 5, 6};

/// Abaqus C3D8 face label number (S1..S6) of each VTK face: Abaqus' faces are
/// S1:(1,2,3,4) S2:(5,8,7,6) S3:(1,5,6,2) S4:(2,6,7,3) S5:(3,7,8,4) S6:(4,8,5,1).
inline constexpr std::array<int, 6> kAbaqusFaceOfVtkFace = {6, 4, 3, 5, 1, 2};

}  // namespace isohex::io
