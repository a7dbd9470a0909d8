#include "isohex/surface/surface_graph.hpp"

#include <algorithm>
#include <array>
#include <tuple>

namespace isohex::surface_detail {

namespace {

Vec3 quad_normal(const HexMesh& mesh, const Quad& q) {
  const auto& p = mesh.points;
  const Vec3 n = (p[q[2]] - p[q[0]]).cross(p[q[3]] - p[q[1]]);
  const double len = n.norm();
  return len > 0 ? Vec3(n / len) : Vec3::Zero();
}

// CSR from (key, value) pairs sorted by key then value.
Incidence pairs_to_csr(const std::vector<std::array<Index, 2>>& pairs, Index num_vertices) {
  Incidence inc;
  inc.offsets.assign(static_cast<std::size_t>(num_vertices) + 1, 0);
  for (const auto& [a, b] : pairs) ++inc.offsets[a + 1];
  for (std::size_t i = 1; i < inc.offsets.size(); ++i) inc.offsets[i] += inc.offsets[i - 1];
  inc.ids.reserve(pairs.size());
  for (const auto& pr : pairs) inc.ids.push_back(pr[1]);
  return inc;
}

}  // namespace

SurfaceGraph build_surface_graph(const HexMesh& mesh, double crease_cos, const std::function<Vec3(Index)>& vertex_normal,
                                 double vertex_crease_cos) {
  SurfaceGraph g;
  const Index nv = mesh.num_vertices();
  const std::vector<QuadFace> faces = build_quads(mesh);
  g.quads = boundary_quads(faces);
  for (const QuadFace& f : faces)
    if (f.is_boundary()) {
      g.quad_hex.push_back(f.hex[0]);
      g.quad_face.push_back(f.local[0]);
    }
  g.vertex_quads = vertex_cells(g.quads, nv);
  g.vertex_hexes = vertex_hexes(mesh);
  g.on_boundary.assign(static_cast<std::size_t>(nv), 0);
  g.on_crease.assign(static_cast<std::size_t>(nv), 0);
  g.on_feature.assign(static_cast<std::size_t>(nv), 0);
  for (const Quad& q : g.quads)
    for (Index v : q) g.on_boundary[v] = 1;

  // Boundary edges with the quads on either side: (low, high, quad), sorted.
  std::vector<std::tuple<Index, Index, Index>> edges;
  edges.reserve(g.quads.size() * 4);
  for (Index qi = 0; qi < static_cast<Index>(g.quads.size()); ++qi)
    for (int k = 0; k < 4; ++k) {
      const Index a = g.quads[qi][k], b = g.quads[qi][(k + 1) % 4];
      edges.emplace_back(std::min(a, b), std::max(a, b), qi);
    }
  std::sort(edges.begin(), edges.end());

  std::vector<std::array<Index, 2>> neighbour_pairs;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && std::get<0>(edges[j]) == std::get<0>(edges[i]) &&
           std::get<1>(edges[j]) == std::get<1>(edges[i]))
      ++j;
    const Index a = std::get<0>(edges[i]), b = std::get<1>(edges[i]);
    neighbour_pairs.push_back({a, b});
    neighbour_pairs.push_back({b, a});
    bool crease = j - i != 2;  // a non-manifold edge: no tangent plane to slide in
    if (!crease) {
      const Vec3 n0 = quad_normal(mesh, g.quads[std::get<2>(edges[i])]);
      const Vec3 n1 = quad_normal(mesh, g.quads[std::get<2>(edges[i + 1])]);
      crease = n0.dot(n1) < crease_cos;
    }
    if (crease) g.on_crease[a] = g.on_crease[b] = 1;
    if (crease && (j - i != 2 || !vertex_normal || vertex_normal(a).dot(vertex_normal(b)) < vertex_crease_cos))
      g.on_feature[a] = g.on_feature[b] = 1;
    i = j;
  }
  std::sort(neighbour_pairs.begin(), neighbour_pairs.end());
  g.boundary_neighbours = pairs_to_csr(neighbour_pairs, nv);
  return g;
}

std::vector<Index> interior_band(const HexMesh& mesh, const SurfaceGraph& graph, int layers,
                                 const std::vector<std::uint8_t>& pinned) {
  const Index nv = mesh.num_vertices();
  std::vector<int> depth(static_cast<std::size_t>(nv), -1);
  std::vector<Index> front;
  for (Index v = 0; v < nv; ++v)
    if (graph.on_boundary[v]) {
      depth[v] = 0;
      front.push_back(v);
    }
  std::vector<Index> band;
  for (int layer = 1; layer <= layers && !front.empty(); ++layer) {
    std::vector<Index> next;
    for (Index v : front)
      for (Index k = graph.vertex_hexes.offsets[v]; k < graph.vertex_hexes.offsets[v + 1]; ++k)
        for (Index w : mesh.hexes[graph.vertex_hexes.ids[k]])
          if (depth[w] < 0) {
            depth[w] = layer;
            next.push_back(w);
          }
    for (Index w : next)
      if (pinned.empty() || !pinned[w]) band.push_back(w);
    front = std::move(next);
  }
  std::sort(band.begin(), band.end());
  return band;
}

std::vector<std::vector<Index>> colour_classes(const std::vector<Index>& vertices, const HexMesh& mesh,
                                               const Incidence& vertex_hexes) {
  std::vector<int> colour(mesh.points.size(), -1);
  std::vector<std::vector<Index>> classes;
  std::vector<char> used;
  for (Index v : vertices) {
    used.assign(classes.size() + 1, 0);
    for (Index k = vertex_hexes.offsets[v]; k < vertex_hexes.offsets[v + 1]; ++k)
      for (Index w : mesh.hexes[vertex_hexes.ids[k]])
        if (colour[w] >= 0) used[static_cast<std::size_t>(colour[w])] = 1;
    const auto c = static_cast<std::size_t>(std::find(used.begin(), used.end(), 0) - used.begin());
    if (c == classes.size()) classes.emplace_back();
    classes[c].push_back(v);
    colour[v] = static_cast<int>(c);
  }
  return classes;
}

std::vector<std::vector<Index>> read_disjoint_classes(const std::vector<Index>& vertices, const SurfaceGraph& graph,
                                                      const HexMesh* guarded) {
  const auto reads = [&](Index v, auto&& f) {
    const auto each_quad_vertex = [&](Index w) {
      for (Index k = graph.vertex_quads.offsets[w]; k < graph.vertex_quads.offsets[w + 1]; ++k)
        for (Index x : graph.quads[graph.vertex_quads.ids[k]]) f(x);
    };
    each_quad_vertex(v);
    // The hex guard reads every corner of v's hexes, which reach boundary vertices beyond the
    // quads (a hex with two boundary faces: a slab one cell thick).
    if (guarded)
      for (Index k = graph.vertex_hexes.offsets[v]; k < graph.vertex_hexes.offsets[v + 1]; ++k)
        for (Index x : guarded->hexes[graph.vertex_hexes.ids[k]]) f(x);
    for (Index k = graph.boundary_neighbours.offsets[v]; k < graph.boundary_neighbours.offsets[v + 1]; ++k)
      each_quad_vertex(graph.boundary_neighbours.ids[k]);
  };
  // Who reads whom, both ways: the readers of each vertex, bucketed by counting (the max–min
  // passes build these classes every pass; sorting every (read, reader) pair and a hash map of
  // colours were a tenth of cthead h 2's surface stage). Repeats in a bucket mark twice, which
  // changes nothing.
  const std::size_t nv = graph.vertex_quads.offsets.size() - 1;
  std::vector<Index> first(nv + 1, 0);
  for (Index v : vertices) reads(v, [&](Index x) { ++first[static_cast<std::size_t>(x) + 1]; });
  for (std::size_t x = 0; x < nv; ++x) first[x + 1] += first[x];
  std::vector<Index> readers(static_cast<std::size_t>(first[nv]));
  {
    std::vector<Index> next(first.begin(), first.end() - 1);
    for (Index v : vertices) reads(v, [&](Index x) { readers[static_cast<std::size_t>(next[static_cast<std::size_t>(x)]++)] = v; });
  }
  std::vector<int> colour(nv, -1);
  std::vector<std::vector<Index>> classes;
  std::vector<char> used;
  for (Index v : vertices) {
    used.assign(classes.size() + 1, 0);
    const auto mark = [&](Index x) {
      if (const int c = colour[static_cast<std::size_t>(x)]; c >= 0) used[static_cast<std::size_t>(c)] = 1;
    };
    reads(v, mark);  // those v reads
    for (Index k = first[static_cast<std::size_t>(v)]; k < first[static_cast<std::size_t>(v) + 1]; ++k)
      mark(readers[static_cast<std::size_t>(k)]);  // those that read v
    const auto c = static_cast<std::size_t>(std::find(used.begin(), used.end(), 0) - used.begin());
    if (c == classes.size()) classes.emplace_back();
    classes[c].push_back(v);
    colour[static_cast<std::size_t>(v)] = static_cast<int>(c);
  }
  return classes;
}

}  // namespace isohex::surface_detail
