#pragma once
/// \file hex_selection.hpp
/// \brief Sets of hexes from command-line specifications, shared by the commands that act
/// on part of a mesh (`isohex pillow --shrink-set`, `isohex refine --hexes`).

#include "isohex/mesh/hex_mesh.hpp"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace isohex {

/// A set of hexes (one flag per hex, 1 = selected) from a specification:
/// - `all_keyword` (e.g. `all`, or `boundary` for pillowing): every hex;
/// - `block:ID`: the hexes of one block;
/// - `region:EXPR`: hexes whose centroid is inside the implicit shape EXPR (see implicit.hpp);
/// - `ids:FILE`: one hex id per line; blank lines and lines starting with '#' ignored.
///
/// Throws isohex::Error, prefixed with `context` (e.g. "shrink set"), for an unknown kind, a
/// bad or out-of-range id (naming the file and line) or a bad shape expression. An empty
/// result is not an error here; callers decide.
std::vector<std::uint8_t> select_hexes(const HexMesh& mesh, const std::string& spec, std::string_view context,
                                       std::string_view all_keyword = "all");

/// Flags (1 = listed) for `count` ids read from `file`: one id per line, blank lines and lines
/// starting with '#' ignored. Throws isohex::Error, prefixed with `context`, naming the file
/// and line of a bad or out-of-range id (`noun`: "hex", "vertex").
std::vector<std::uint8_t> read_id_list(const std::string& file, std::size_t count, std::string_view noun,
                                       std::string_view context);

}  // namespace isohex
