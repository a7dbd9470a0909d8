#include "isohex/mesh/validate.hpp"

#include "isohex/mesh/topology.hpp"
#include "isohex/mesh/union_find.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace isohex {

const char* fault_kind_name(FaultKind k) {
  switch (k) {
    case FaultKind::non_finite_coordinate: return "non_finite_coordinate";
    case FaultKind::id_out_of_range: return "id_out_of_range";
    case FaultKind::repeated_vertex: return "repeated_vertex";
    case FaultKind::quad_shared_by_many: return "quad_shared_by_many";
    case FaultKind::inconsistent_orientation: return "inconsistent_orientation";
    case FaultKind::non_manifold_edge: return "non_manifold_edge";
    case FaultKind::non_manifold_vertex: return "non_manifold_vertex";
    case FaultKind::unused_vertex: return "unused_vertex";
  }
  return "unknown";
}

bool is_error(FaultKind k) { return k != FaultKind::unused_vertex; }

std::size_t ValidationReport::num_errors() const {
  std::size_t n = 0;
  for (auto [k, c] : counts)
    if (is_error(k)) n += c;
  return n;
}

std::size_t ValidationReport::num_warnings() const { return count(FaultKind::unused_vertex); }

namespace {

class Collector {
 public:
  Collector(ValidationReport& r, std::size_t max) : r_(r), max_(max) {}
  template <class... Args>
  void add(FaultKind k, Index element, fmt::format_string<Args...> f, Args&&... args) {
    if (r_.counts[k]++ < max_) r_.faults.push_back({k, element, fmt::format(f, std::forward<Args>(args)...)});
  }

 private:
  ValidationReport& r_;
  std::size_t max_;
};

void check_vertices_and_ids(const HexMesh& mesh, Collector& out, ValidationReport& r) {
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    const Vec3& p = mesh.points[v];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
      out.add(FaultKind::non_finite_coordinate, v, "vertex {} has a non-finite coordinate ({}, {}, {})", v, p.x(),
              p.y(), p.z());
  }
  const Index n = mesh.num_vertices();
  for (Index h = 0; h < mesh.num_hexes(); ++h) {
    const Hex& hex = mesh.hexes[h];
    for (int c = 0; c < 8; ++c)
      if (hex[c] < 0 || hex[c] >= n)
        out.add(FaultKind::id_out_of_range, h, "hex {}: vertex id {} at corner {} is out of range [0, {})", h, hex[c],
                c, n);
    for (int a = 0; a < 8; ++a)
      for (int b = a + 1; b < 8; ++b)
        if (hex[a] == hex[b])
          out.add(FaultKind::repeated_vertex, h, "hex {}: vertex {} appears at corners {} and {}", h, hex[a], a, b);
  }
  r.topology_checked = r.count(FaultKind::id_out_of_range) == 0;
}

// True if `b` traverses the same four vertices as `a` in the opposite cyclic direction.
bool reversed_cycle(const Quad& a, const Quad& b) {
  for (int s = 0; s < 4; ++s)
    if (b[s] == a[0]) return b[(s + 1) % 4] == a[3] && b[(s + 2) % 4] == a[2] && b[(s + 3) % 4] == a[1];
  return false;
}

void check_quads(const HexMesh& mesh, const std::vector<QuadFace>& quads, Collector& out) {
  for (std::size_t i = 0; i < quads.size(); ++i) {
    const QuadFace& q = quads[i];
    if (q.extra_hexes > 0)
      out.add(FaultKind::quad_shared_by_many, static_cast<Index>(i), "quad ({}) is shared by {} hexes (hexes {}, {}, ...)",
              fmt::join(q.vertices, ", "), q.extra_hexes + 2, q.hex[0], q.hex[1]);
    if (q.is_boundary()) continue;
    const Hex& h1 = mesh.hexes[q.hex[1]];
    const auto& f = kHexFaces[q.local[1]];
    const Quad other = {h1[f[0]], h1[f[1]], h1[f[2]], h1[f[3]]};
    if (!reversed_cycle(q.vertices, other))
      out.add(FaultKind::inconsistent_orientation, q.hex[1],
              "hexes {} and {} traverse their shared quad ({}) in the same direction: one of them has mirrored "
              "(inverted) node order",
              q.hex[0], q.hex[1], fmt::join(q.vertices, ", "));
  }
}

void check_boundary(const HexMesh& mesh, const std::vector<Quad>& boundary, Collector& out, ValidationReport& r) {
  r.num_boundary_quads = boundary.size();
  // Boundary edges with the number of boundary quads using each.
  std::vector<std::array<Index, 2>> edges;
  edges.reserve(boundary.size() * 4);
  for (const Quad& q : boundary)
    for (int i = 0; i < 4; ++i) edges.push_back({std::min(q[i], q[(i + 1) % 4]), std::max(q[i], q[(i + 1) % 4])});
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    ++r.num_boundary_edges;
    if (j - i != 2)
      out.add(FaultKind::non_manifold_edge, edges[i][0], "boundary edge ({}, {}) is used by {} boundary quads (expected 2)",
              edges[i][0], edges[i][1], j - i);
    i = j;
  }

  // Vertex links: around a manifold boundary vertex the quads form a single fan, so the
  // link edges (the vertex's two neighbours in each quad) form one connected cycle.
  const Incidence inc = vertex_cells(boundary, mesh.num_vertices());
  detail::UnionFind components(mesh.points.size());
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    const std::size_t n = inc.count(v);
    if (n == 0) continue;
    ++r.num_boundary_vertices;
    std::vector<std::array<Index, 2>> link;
    for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) {
      const Quad& q = boundary[inc.ids[k]];
      const int i = static_cast<int>(std::find(q.begin(), q.end(), v) - q.begin());
      link.push_back({q[(i + 1) % 4], q[(i + 3) % 4]});
      components.unite(v, q[(i + 1) % 4]);
    }
    // Count connected pieces of the link graph (few nodes: a quadratic pass is fine).
    std::vector<Index> nodes;
    for (auto& e : link) nodes.insert(nodes.end(), e.begin(), e.end());
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    detail::UnionFind pieces(nodes.size());
    auto at = [&](Index x) { return static_cast<Index>(std::lower_bound(nodes.begin(), nodes.end(), x) - nodes.begin()); };
    for (auto& e : link) pieces.unite(at(e[0]), at(e[1]));
    std::size_t npieces = 0;
    for (Index i = 0; i < static_cast<Index>(nodes.size()); ++i) npieces += pieces.find(i) == i;
    if (npieces > 1)
      out.add(FaultKind::non_manifold_vertex, v,
              "boundary vertex {} is non-manifold: its {} boundary quads form {} separate fans", v, n, npieces);
  }
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    if (inc.count(v) > 0 && components.find(v) == v) ++r.num_boundary_components;
  r.euler_characteristic = static_cast<long>(r.num_boundary_vertices) - static_cast<long>(r.num_boundary_edges) +
                           static_cast<long>(r.num_boundary_quads);
}

void check_unused(const HexMesh& mesh, Collector& out) {
  std::vector<std::uint8_t> used(mesh.points.size(), 0);
  for (const Hex& h : mesh.hexes)
    for (Index v : h) used[v] = 1;
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    if (!used[v]) out.add(FaultKind::unused_vertex, v, "vertex {} is used by no hex", v);
}

}  // namespace

ValidationReport validate(const HexMesh& mesh, const ValidateOptions& options) {
  ValidationReport r;
  Collector out(r, options.max_messages);
  check_vertices_and_ids(mesh, out, r);
  if (!r.topology_checked) return r;
  std::vector<Quad> boundary;
  {
    // Every quad (cthead h 2: 58 MB) only while it is checked: the boundary's checks allocate
    // their own, and this was the peak at the end of `isohex mesh`.
    const std::vector<QuadFace> quads = build_quads(mesh);
    r.num_quads = quads.size();
    check_quads(mesh, quads, out);
    boundary = boundary_quads(quads);
  }
  check_boundary(mesh, boundary, out, r);
  check_unused(mesh, out);
  return r;
}

}  // namespace isohex
