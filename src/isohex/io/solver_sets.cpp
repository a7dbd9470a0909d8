#include "isohex/io/solver_sets.hpp"

#include "isohex/io/text_scanner.hpp"
#include "isohex/mesh/topology.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <limits>

namespace isohex::io {

BlockTable block_table(const HexMesh& mesh) {
  BlockTable t;
  if (mesh.hexes.empty()) return t;
  if (mesh.blocks.empty()) {
    t.values = {0};
  } else {
    t.values = mesh.blocks;
    std::sort(t.values.begin(), t.values.end());
    t.values.erase(std::unique(t.values.begin(), t.values.end()), t.values.end());
  }
  const bool positive = t.values.front() >= 1;
  t.file_ids.resize(t.values.size());
  for (std::size_t i = 0; i < t.values.size(); ++i)
    t.file_ids[i] = positive ? t.values[i] : static_cast<Index>(i + 1);
  t.of_hex.resize(mesh.hexes.size());
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h) {
    const Index b = mesh.block(static_cast<Index>(h));
    t.of_hex[h] = static_cast<Index>(std::lower_bound(t.values.begin(), t.values.end(), b) - t.values.begin());
  }
  return t;
}

std::string block_name(Index value) { return fmt::format("block_{}", value); }

bool parse_block_name(std::string_view name, Index& value) {
  constexpr std::string_view prefix = "block_";
  if (!name.starts_with(prefix)) return false;
  const std::string_view digits = name.substr(prefix.size());
  std::int64_t v = 0;
  // "+5" or " 5" would not round-trip through block_name: refuse them.
  if (digits.empty() || digits.front() == '+' || !parse_int(digits, v)) return false;
  if (v < std::numeric_limits<Index>::min() || v > std::numeric_limits<Index>::max()) return false;
  value = static_cast<Index>(v);
  return true;
}

std::vector<Index> blocks_from_sets(const std::vector<std::string>& names, const std::vector<Index>& file_ids,
                                    const std::vector<Index>& set_of_hex) {
  std::vector<Index> value(file_ids);
  bool named = true;
  for (std::size_t i = 0; i < names.size() && named; ++i) named = parse_block_name(names[i], value[i]);
  if (!named) value = file_ids;
  std::vector<Index> blocks(set_of_hex.size());
  bool any = false;
  for (std::size_t h = 0; h < set_of_hex.size(); ++h) {
    blocks[h] = value[static_cast<std::size_t>(set_of_hex[h])];
    any = any || blocks[h] != 0;
  }
  if (!any) blocks.clear();
  return blocks;
}

std::vector<BoundaryFace> boundary_faces(const HexMesh& mesh) {
  std::vector<BoundaryFace> out;
  for (const QuadFace& q : build_quads(mesh))
    if (q.is_boundary()) out.push_back({q.hex[0], q.local[0]});
  return out;
}

std::vector<Index> boundary_nodes(const HexMesh& mesh) {
  const std::vector<std::uint8_t> mask = boundary_vertex_mask(mesh);
  std::vector<Index> out;
  for (std::size_t v = 0; v < mask.size(); ++v)
    if (mask[v]) out.push_back(static_cast<Index>(v));
  return out;
}

}  // namespace isohex::io
