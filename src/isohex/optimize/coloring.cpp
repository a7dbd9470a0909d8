// Fixed-vertex masks, snapshots of the free vertices, and the vertex colouring behind the
// parallel Gauss–Seidel sweeps.
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"

#include <algorithm>

namespace isohex {

std::vector<std::uint8_t> fixed_mask(const HexMesh& mesh, FixedVertices which) {
  switch (which) {
    case FixedVertices::boundary:
      return boundary_vertex_mask(mesh);
    case FixedVertices::file:
      if (mesh.has_fixed()) return mesh.fixed;
      break;
    case FixedVertices::none:
      break;
  }
  return std::vector<std::uint8_t>(mesh.points.size(), 0);
}

VertexColoring color_vertices(const HexMesh& mesh, const std::vector<std::uint8_t>& fixed, const Incidence* given) {
  Incidence own;
  const Incidence& inc = opt::incidence_of(mesh, given, own);
  std::vector<int> color(mesh.points.size(), -1);
  std::vector<Index> stamp;  // stamp[c] == v: colour c is taken by a neighbour of v
  VertexColoring out;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    if (!fixed.empty() && fixed[v]) continue;
    if (inc.count(v) == 0) continue;  // an unused vertex has nothing to optimise
    for (Index i = inc.offsets[v]; i < inc.offsets[v + 1]; ++i)
      for (Index w : mesh.hexes[inc.ids[i]])
        if (w != v && color[w] >= 0) stamp[color[w]] = v;
    int c = 0;
    while (c < static_cast<int>(stamp.size()) && stamp[c] == v) ++c;
    if (c == static_cast<int>(stamp.size())) {
      stamp.push_back(-1);
      out.colors.emplace_back();
    }
    color[v] = c;
    out.colors[c].push_back(v);  // v ascending: each colour's list is sorted
  }
  return out;
}

PointSnapshot::PointSnapshot(const HexMesh& mesh, const std::vector<std::uint8_t>& fixed) {
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    if (fixed.empty() || !fixed[v]) ids_.push_back(v);
  whole_ = ids_.size() * (sizeof(Index) + sizeof(Vec3)) >= mesh.points.size() * sizeof(Vec3);
  if (whole_) std::vector<Index>().swap(ids_);  // every point: cheaper than ids and places
  at_.resize(whole_ ? mesh.points.size() : ids_.size());
  take(mesh);
}

void PointSnapshot::take(const HexMesh& mesh) {
  if (whole_) {
    std::copy(mesh.points.begin(), mesh.points.end(), at_.begin());
    return;
  }
  for (std::size_t i = 0; i < ids_.size(); ++i) at_[i] = mesh.points[ids_[i]];
}

void PointSnapshot::restore(HexMesh& mesh) const {
  if (whole_) {
    std::copy(at_.begin(), at_.end(), mesh.points.begin());
    return;
  }
  for (std::size_t i = 0; i < ids_.size(); ++i) mesh.points[ids_[i]] = at_[i];
}

}  // namespace isohex
