// Dual sheets: union-find over the parallel edges of every hex.
#include "isohex/sheets/dual_sheets.hpp"

#include "isohex/error.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/mesh/union_find.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace isohex {

namespace {

/// kHexEdges indices of the three groups of four parallel edges.
constexpr std::array<std::array<int, 4>, 3> kEdgeGroups = {{{0, 2, 4, 6}, {1, 3, 5, 7}, {8, 9, 10, 11}}};

/// The edge group perpendicular to face f of kHexFaces (faces come in opposite pairs 0/1, 2/3, 4/5).
constexpr int perpendicular_group(int face) { return face / 2; }

}  // namespace

SheetReport extract_sheets(const HexMesh& mesh) {
  for (Index h = 0; h < mesh.num_hexes(); ++h)
    for (Index v : mesh.hexes[h])
      if (v < 0 || v >= mesh.num_vertices())
        throw Error(fmt::format("sheets: hex {} names vertex {}, out of range [0, {})", h, v, mesh.num_vertices()));
  const std::vector<std::array<Index, 2>> edges = build_edges(mesh);
  auto edge_id = [&](Index a, Index b) {
    const std::array<Index, 2> key{std::min(a, b), std::max(a, b)};
    return static_cast<Index>(std::lower_bound(edges.begin(), edges.end(), key) - edges.begin());
  };
  // Edge ids per hex edge, kept so that the second pass needs no searches.
  std::vector<std::array<Index, 12>> hex_edges(mesh.hexes.size());
  detail::UnionFind uf(edges.size());
  for (Index h = 0; h < mesh.num_hexes(); ++h) {
    const Hex& x = mesh.hexes[h];
    for (int e = 0; e < 12; ++e) hex_edges[h][e] = edge_id(x[kHexEdges[e][0]], x[kHexEdges[e][1]]);
    for (const auto& g : kEdgeGroups)
      for (int i = 1; i < 4; ++i) uf.unite(hex_edges[h][g[0]], hex_edges[h][g[i]]);
  }
  // Dense sheet ids in the order of their smallest edge.
  SheetReport r;
  std::vector<Index> sheet_of_root(edges.size(), -1);
  for (Index e = 0; e < static_cast<Index>(edges.size()); ++e) {
    Index& s = sheet_of_root[uf.find(e)];
    if (s < 0) s = static_cast<Index>(r.num_sheets++);
  }
  r.sheet_sizes.assign(r.num_sheets, 0);
  std::vector<char> self(r.num_sheets, 0);
  r.hex_sheets.resize(mesh.hexes.size());
  for (Index h = 0; h < mesh.num_hexes(); ++h) {
    auto& s = r.hex_sheets[h];
    for (int g = 0; g < 3; ++g) s[g] = sheet_of_root[uf.find(hex_edges[h][kEdgeGroups[g][0]])];
    ++r.sheet_sizes[s[0]];
    if (s[1] != s[0]) ++r.sheet_sizes[s[1]];
    if (s[2] != s[0] && s[2] != s[1]) ++r.sheet_sizes[s[2]];
    const bool meets_itself = s[0] == s[1] || s[0] == s[2] || s[1] == s[2];
    if (meets_itself) {
      ++r.self_intersecting_hexes;
      self[s[0] == s[1] || s[0] == s[2] ? s[0] : s[1]] = 1;
    }
  }
  for (Index s = 0; s < static_cast<Index>(r.num_sheets); ++s)
    if (self[s]) r.self_intersecting.push_back(s);

  // Boundary components through shared vertices of boundary quads (the same as through
  // shared edges on a valid mesh, whose boundary is manifold).
  const std::vector<QuadFace> quads = build_quads(mesh);
  detail::UnionFind comp(mesh.points.size());
  std::vector<std::uint8_t> boundary_faces(mesh.hexes.size(), 0);
  for (const QuadFace& q : quads)
    if (q.is_boundary()) {
      ++boundary_faces[q.hex[0]];
      for (int i = 1; i < 4; ++i) comp.unite(q.vertices[0], q.vertices[i]);
    }
  std::vector<Index> component_of_root(mesh.points.size(), -1);
  for (const QuadFace& q : quads) {
    if (!q.is_boundary()) continue;
    Index& c = component_of_root[comp.find(q.vertices[0])];
    if (c < 0) {
      c = static_cast<Index>(r.boundary_capture.size());
      r.boundary_capture.emplace_back();
      r.boundary_component_quads.push_back(0);
    }
    ++r.boundary_component_quads[c];
    r.boundary_capture[c].push_back(r.hex_sheets[q.hex[0]][perpendicular_group(q.local[0])]);
  }
  for (auto& sheets : r.boundary_capture) {
    std::sort(sheets.begin(), sheets.end());
    sheets.erase(std::unique(sheets.begin(), sheets.end()), sheets.end());
  }
  r.multi_boundary_hexes = static_cast<std::size_t>(
      std::count_if(boundary_faces.begin(), boundary_faces.end(), [](std::uint8_t n) { return n >= 2; }));
  return r;
}

}  // namespace isohex
