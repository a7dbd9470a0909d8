// Splitting the interface vertices of a pillowing into groups (see pillow_split.hpp).
#include "isohex/sheets/pillow_split.hpp"

#include "isohex/mesh/union_find.hpp"
#include "isohex/quality/hex_quality.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <tuple>

namespace isohex::detail {

namespace {

constexpr Index kExterior = -1;
enum Merge : std::uint8_t { kNone = 0, kOutside = 1, kShrink = 2 };

/// An interface edge whose side faces need pairing.
struct PinchedEdge {
  Index v, w;
  bool chain;                 // ends on the boundary with no exterior cell: side faces may stay single
  std::vector<Index> cells;   // hexes around the edge (+ kExterior)
  std::vector<Index> quads;   // interface quads around the edge
  Merge merge;
};

/// The groups around one vertex.
struct Local {
  std::vector<Index> cells;   // hexes around v ascending, then kExterior if present
  std::vector<Index> group;   // per cell
  std::vector<char> shrink;   // per group
  std::vector<Vec3> dir;      // per group: unit direction of its move
  std::vector<double> margin; // per group: min cosine between dir and its corner normals
  int keeper = -1;
  bool feasible = true;

  [[nodiscard]] Index group_of(Index cell) const {
    if (cell == kExterior) return group.back();
    return group[std::lower_bound(cells.begin(), cells.end() - (cells.back() == kExterior), cell) - cells.begin()];
  }
};

constexpr double kSeen = 1e-9;  // a direction "sees" a corner if its cosine exceeds this

class Splitter {
 public:
  Splitter(const HexMesh& mesh, const std::vector<std::uint8_t>& in, const std::vector<std::array<Index, 6>>& nb,
           const std::vector<InterfaceQuad>& iq, const PillowOptions& opt, const Incidence& hex_inc)
      : m_(mesh), in_(in), nb_(nb), iq_(iq), opt_(opt), hex_inc_(hex_inc) {
    std::vector<Quad> quads;
    quads.reserve(iq.size());
    for (const auto& q : iq) quads.push_back(q.v);
    iq_inc_ = vertex_cells(quads, mesh.num_vertices());
    // The boundary vertices from the faces with no hex across (boundary_vertex_mask() would
    // sort every face again: on cthead h 2 that was the pipeline's memory peak).
    if (opt.include_boundary) {
      boundary_.assign(mesh.points.size(), 0);
      for (std::size_t h = 0; h < nb.size(); ++h)
        for (int f = 0; f < 6; ++f)
          if (nb[h][static_cast<std::size_t>(f)] < 0)
            for (int k = 0; k < 4; ++k) boundary_[mesh.hexes[h][kHexFaces[f][k]]] = 1;
    }
    find_pinched_edges();
  }

  InterfaceSplit run() {
    InterfaceSplit s;
    s.pinched_edges = edges_.size();
    search();
    for (const PinchedEdge& e : edges_) {
      const Local lv = analyze(e.v);
      if (!edge_ok(e, lv, analyze(e.w))) {  // never seen; flipping a hex there is the way out
        s.unpaired_edges.push_back({e.v, e.w});
        s.flip_candidates.emplace_back(e.v, flip_candidate(lv));
      }
      s.flipped_edges += e.merge == kShrink;
    }
    emit(s);
    return s;
  }

 private:
  bool outside(Index cell) const { return cell == kExterior || !in_[cell]; }

  bool face_has(Index h, int f, Index v) const {
    for (int c : kHexFaces[f])
      if (m_.hexes[h][c] == v) return true;
    return false;
  }

  static int corner(const Quad& q, Index v) { return static_cast<int>(std::find(q.begin(), q.end(), v) - q.begin()); }

  /// Interface edges with more than two interface quads (or more than one on a chain).
  void find_pinched_edges() {
    std::vector<std::pair<std::uint64_t, Index>> keyed;
    keyed.reserve(4 * iq_.size());
    for (Index q = 0; q < static_cast<Index>(iq_.size()); ++q)
      for (int k = 0; k < 4; ++k) {
        const Index a = iq_[q].v[k], b = iq_[q].v[(k + 1) % 4];
        const auto key = static_cast<std::uint64_t>(std::min(a, b)) << 32 | static_cast<std::uint32_t>(std::max(a, b));
        keyed.emplace_back(key, q);
      }
    std::sort(keyed.begin(), keyed.end());
    for (std::size_t i = 0, j; i < keyed.size(); i = j) {
      for (j = i; j < keyed.size() && keyed[j].first == keyed[i].first; ++j) {}
      if (j - i < 2) continue;
      PinchedEdge e{static_cast<Index>(keyed[i].first >> 32), static_cast<Index>(keyed[i].first & 0xffffffffu),
                    false, {}, {}, kNone};
      for (std::size_t k = i; k < j; ++k) e.quads.push_back(keyed[k].second);
      for (Index k = hex_inc_.offsets[e.v]; k < hex_inc_.offsets[e.v + 1]; ++k) {
        const Hex& h = m_.hexes[hex_inc_.ids[k]];
        if (std::find(h.begin(), h.end(), e.w) != h.end()) e.cells.push_back(hex_inc_.ids[k]);
      }
      // Around a boundary edge the hexes form a chain; the exterior closes it into a cycle
      // when boundary quads are interface quads.
      bool on_boundary = false;
      for (Index h : e.cells)
        for (int f = 0; f < 6; ++f)
          on_boundary |= nb_[h][f] < 0 && face_has(h, f, e.v) && face_has(h, f, e.w);
      if (on_boundary && opt_.include_boundary) e.cells.push_back(kExterior);
      e.chain = on_boundary && !opt_.include_boundary;
      if (!e.chain && e.quads.size() < 4) continue;  // a cycle with two: the sheet simply passes
      // Default: merge the outside, so each face-connected piece of the shrink set gets its own
      // copy (the shrink set is pillowed as separate pieces where it pinches).
      e.merge = e.chain ? kNone : kOutside;
      edges_.push_back(std::move(e));
    }
    for (Index e = 0; e < static_cast<Index>(edges_.size()); ++e) {
      at_.emplace_back(edges_[e].v, e);
      at_.emplace_back(edges_[e].w, e);
    }
    std::sort(at_.begin(), at_.end());
  }

  std::vector<Index> edges_at(Index v) const {
    std::vector<Index> out;
    for (auto it = std::lower_bound(at_.begin(), at_.end(), std::pair<Index, Index>(v, -1));
         it != at_.end() && it->first == v; ++it)
      out.push_back(it->second);
    return out;
  }

  Local analyze(Index v) const {
    Local L;
    for (Index k = hex_inc_.offsets[v]; k < hex_inc_.offsets[v + 1]; ++k) L.cells.push_back(hex_inc_.ids[k]);
    const Index n = static_cast<Index>(L.cells.size());
    const bool ext = opt_.include_boundary && boundary_[v];
    if (ext) L.cells.push_back(kExterior);
    auto local = [&](Index h) {
      return h == kExterior ? n : static_cast<Index>(std::lower_bound(L.cells.begin(), L.cells.begin() + n, h) -
                                                     L.cells.begin());
    };
    UnionFind uf(L.cells.size());
    for (Index i = 0; i < n; ++i) {
      const Index h = L.cells[i];
      for (int f = 0; f < 6; ++f) {
        if (!face_has(h, f, v)) continue;
        const Index o = nb_[h][f];
        if (o >= 0 ? in_[o] == in_[h] : ext && !in_[h]) uf.unite(i, local(o));
      }
    }
    for (Index e : edges_at(v)) {
      const PinchedEdge& pe = edges_[e];
      if (pe.merge == kNone) continue;
      Index first = -1;
      for (Index c : pe.cells)
        if (outside(c) == (pe.merge == kOutside)) {
          if (first < 0) first = local(c);
          else uf.unite(first, local(c));
        }
    }
    std::vector<Index> root_group(L.cells.size(), -1);
    for (std::size_t i = 0; i < L.cells.size(); ++i) {
      Index& g = root_group[uf.find(static_cast<Index>(i))];
      if (g < 0) {
        g = static_cast<Index>(L.shrink.size());
        L.shrink.push_back(!outside(L.cells[i]));
      }
      L.group.push_back(g);
    }
    // Corner normals of the interface quads at v, oriented into each group.
    const std::size_t G = L.shrink.size();
    std::vector<std::vector<Vec3>> normals(G);
    std::vector<Vec3> mean(G, Vec3::Zero());
    for (Index k = iq_inc_.offsets[v]; k < iq_inc_.offsets[v + 1]; ++k) {
      const InterfaceQuad& q = iq_[iq_inc_.ids[k]];
      const int c = corner(q.v, v);
      const Vec3 nrm = (m_.points[q.v[(c + 3) % 4]] - m_.points[v]).cross(m_.points[q.v[(c + 1) % 4]] - m_.points[v]);
      const Vec3 area = area_vector(m_, q.v);
      const Index gs = L.group_of(q.shrink_hex), go = L.group_of(q.outside_hex);
      if (nrm.norm() > 0) {
        normals[gs].push_back(nrm.normalized());
        normals[go].push_back(-nrm.normalized());
      }
      mean[gs] -= area;
      mean[go] += area;
    }
    int blind = 0;
    for (std::size_t g = 0; g < G; ++g) {
      const Vec3 start = mean[g].norm() > 0 ? Vec3(mean[g].normalized()) : Vec3(Vec3::UnitX());
      double lo = 0;
      L.dir.push_back(visible_direction(normals[g], start, lo));
      L.margin.push_back(normals[g].empty() ? -1 : lo);
      blind += !(L.margin.back() > kSeen);
    }
    // The keeper stays: the exterior (the surface must not move), else a blind group (it
    // cannot move), else the least visible group, outside groups first (so that the outside
    // changes as little as possible).
    if (ext) {
      L.keeper = static_cast<int>(L.group.back());
    } else {
      auto key = [&](std::size_t g) { return std::make_tuple(L.margin[g] > kSeen, L.shrink[g] != 0, L.margin[g]); };
      L.keeper = 0;
      for (std::size_t g = 1; g < G; ++g)
        if (key(g) < key(L.keeper)) L.keeper = static_cast<int>(g);
    }
    L.feasible = blind - !(L.margin[L.keeper] > kSeen) == 0;
    return L;
  }

  /// Side faces along the edge pair up: each (outside, shrink) vertex pair at both ends is
  /// used by exactly two of the edge's interface quads (at most two on a chain).
  bool edge_ok(const PinchedEdge& e, const Local& lv, const Local& lw) const {
    std::map<std::array<Index, 4>, int> count;
    for (Index q : e.quads)
      ++count[{lv.group_of(iq_[q].outside_hex), lv.group_of(iq_[q].shrink_hex), lw.group_of(iq_[q].outside_hex),
               lw.group_of(iq_[q].shrink_hex)}];
    for (const auto& [key, c] : count)
      if (c > 2 || (c == 1 && !e.chain)) return false;
    return true;
  }

  /// The groups at v under the current merge sides. They depend only on the merge sides of
  /// v's pinched edges, so they are memoized on those (the searches revisit combinations).
  const Local& groups_at(Index v) const {
    const std::vector<Index> E = edges_at(v);
    std::uint64_t key = 0;
    if (E.size() > 40) {  // the key would overflow: recompute, kept under a key of its own
      memo_.erase({v, ~std::uint64_t{0}});
      key = ~std::uint64_t{0};
    } else {
      for (Index e : E) key = key * 3 + edges_[e].merge;
    }
    auto it = memo_.find({v, key});
    if (it == memo_.end()) it = memo_.emplace(std::pair<Index, std::uint64_t>(v, key), analyze(v)).first;
    return it->second;
  }

  /// Badness of a neighbourhood: blind vertices count 1, unpaired edges 4 (they break the mesh).
  int score(const std::vector<Index>& vertices) const {
    auto get = [&](Index v) -> const Local& { return groups_at(v); };
    int s = 0;
    std::vector<Index> edges;
    for (Index v : vertices) {
      s += !get(v).feasible;
      for (Index e : edges_at(v)) edges.push_back(e);
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    for (Index e : edges) s += 4 * !edge_ok(edges_[e], get(edges_[e].v), get(edges_[e].w));
    return s;
  }

  /// Exact search over the merge sides of the pinched edges connected to `start` (depth
  /// first, checking each vertex as soon as all its edges are set). Local search alone can
  /// stall on a chain of pinched edges where each flip only moves the conflict along; this
  /// settles such chains when a consistent choice exists. Gives up (false) on large
  /// components or after a budget of assignments, leaving the merge sides as they were.
  bool solve_component(Index start) {
    constexpr std::size_t kMaxEdges = 24;
    constexpr long kBudget = 20000;
    std::vector<Index> order, vertices{start};
    for (std::size_t i = 0; i < vertices.size(); ++i)
      for (Index e : edges_at(vertices[i])) {
        if (std::find(order.begin(), order.end(), e) != order.end()) continue;
        order.push_back(e);
        for (Index x : {edges_[e].v, edges_[e].w})
          if (std::find(vertices.begin(), vertices.end(), x) == vertices.end()) vertices.push_back(x);
        if (order.size() > kMaxEdges) return false;
      }
    // Vertices completed by each edge of the order (all their edges set once it is).
    std::vector<std::vector<Index>> completes(order.size());
    for (Index x : vertices) {
      std::size_t last = 0;
      for (Index e : edges_at(x))
        last = std::max(last, static_cast<std::size_t>(std::find(order.begin(), order.end(), e) - order.begin()));
      completes[last].push_back(x);
    }
    std::vector<Merge> saved;
    for (Index e : order) saved.push_back(edges_[e].merge);
    std::vector<Index> complete;
    long budget = kBudget;
    auto ok_after = [&](std::size_t i) {
      for (Index x : completes[i]) {
        if (!groups_at(x).feasible) return false;
        complete.push_back(x);
      }
      for (Index x : completes[i])
        for (Index e : edges_at(x)) {
          const Index y = edges_[e].v == x ? edges_[e].w : edges_[e].v;
          if (std::find(complete.begin(), complete.end(), y) != complete.end() &&
              !edge_ok(edges_[e], groups_at(edges_[e].v), groups_at(edges_[e].w)))
            return false;
        }
      return true;
    };
    std::function<bool(std::size_t)> dfs = [&](std::size_t i) {
      if (i == order.size()) return true;
      const int n = edges_[order[i]].chain ? 3 : 2;
      for (int o = 0; o < n && budget > 0; ++o, --budget) {
        edges_[order[i]].merge = edges_[order[i]].chain ? Merge(o) : Merge(o + 1);
        const std::size_t mark = complete.size();
        if (ok_after(i) && dfs(i + 1)) return true;
        complete.resize(mark);
      }
      return false;
    };
    if (dfs(0)) return true;
    for (std::size_t i = 0; i < order.size(); ++i) edges_[order[i]].merge = saved[i];
    return false;
  }

  /// Local search over the merge sides of the pinched edges at each troubled vertex.
  void search() {
    std::vector<Index> pinched_vertices;
    for (const auto& [v, e] : at_) pinched_vertices.push_back(v);
    pinched_vertices.erase(std::unique(pinched_vertices.begin(), pinched_vertices.end()), pinched_vertices.end());
    for (int round = 0; round < 20; ++round) {
      bool improved = false, troubled = false;
      for (Index v : pinched_vertices) {
        const std::vector<Index> E = edges_at(v);
        std::vector<Index> hood{v};
        for (Index e : E) hood.push_back(edges_[e].v == v ? edges_[e].w : edges_[e].v);
        std::sort(hood.begin(), hood.end());
        hood.erase(std::unique(hood.begin(), hood.end()), hood.end());
        const int current = score(hood);
        if (current == 0) continue;
        troubled = true;
        // Every combination of the edges' options when there are few, else one edge at a time.
        std::vector<Merge> saved;
        for (Index e : E) saved.push_back(edges_[e].merge);
        std::vector<Merge> best = saved;
        int best_score = current;
        auto options = [&](Index e) { return edges_[e].chain ? 3 : 2; };
        long combos = 1;
        for (Index e : E) combos = std::min<long>(combos * options(e), 1 << 12);
        auto set = [&](std::size_t i, int o) { edges_[E[i]].merge = edges_[E[i]].chain ? Merge(o) : Merge(o + 1); };
        auto try_current = [&] {
          const int s = score(hood);
          if (s < best_score) {
            best_score = s;
            for (std::size_t i = 0; i < E.size(); ++i) best[i] = edges_[E[i]].merge;
          }
        };
        if (combos < (1 << 12)) {
          for (long c = 0; c < combos; ++c) {
            long x = c;
            for (std::size_t i = 0; i < E.size(); ++i) {
              set(i, static_cast<int>(x % options(E[i])));
              x /= options(E[i]);
            }
            try_current();
          }
        } else {
          for (std::size_t i = 0; i < E.size(); ++i) {
            for (int o = 0; o < options(E[i]); ++o) {
              set(i, o);
              try_current();
            }
            edges_[E[i]].merge = saved[i];
          }
        }
        for (std::size_t i = 0; i < E.size(); ++i) edges_[E[i]].merge = best[i];
        improved |= best_score < current;
      }
      if (!troubled || !improved) break;
    }
    // What local search left troubled, try exactly, component by component.
    for (Index v : pinched_vertices) {
      std::vector<Index> hood{v};
      for (Index e : edges_at(v)) hood.push_back(edges_[e].v == v ? edges_[e].w : edges_[e].v);
      if (score(hood) > 0) solve_component(v);
    }
  }

  /// Final groups, ids and displacements, vertex by vertex.
  void emit(InterfaceSplit& s) const {
    s.outside_ids.assign(iq_.size(), Quad{-1, -1, -1, -1});
    s.shrink_ids = s.outside_ids;
    s.folded.assign(static_cast<std::size_t>(m_.num_vertices()), 0);
    Index next = m_.num_vertices();
    std::vector<Index> ids;
    for (Index v = 0; v < m_.num_vertices(); ++v) {
      if (iq_inc_.count(v) == 0) continue;
      ++s.interface_vertices;
      const Local L = analyze(v);
      s.folded[v] = !L.feasible;
      if (!L.feasible) {
        // Blind groups forced by the shape of the set (a pinch, or two blind non-exterior
        // groups) can be undone by flipping a hex; a blind group against the exterior is a
        // folded boundary and cannot.
        int blind_inside = 0;
        for (std::size_t g = 0; g < L.shrink.size(); ++g)
          blind_inside += !(L.margin[g] > kSeen) && !(L.cells.back() == kExterior && L.group.back() == Index(g));
        // Only where the hexes around v are sound: on tangled input, blindness comes from the
        // geometry and flips would only wander.
        bool sound = true;
        for (Index c : L.cells)
          if (c != kExterior) {
            const double sj = scaled_jacobian(m_.corners(c));
            sound &= sj > 0 && !is_degenerate(sj);
          }
        if (sound && (!edges_at(v).empty() || blind_inside >= 2)) s.flip_candidates.emplace_back(v, flip_candidate(L));
      }
      ids.assign(L.shrink.size(), -1);
      for (std::size_t g = 0; g < L.shrink.size(); ++g) {
        SplitVertex sv{v, static_cast<int>(g) == L.keeper ? v : next++, Vec3::Zero(), L.shrink[g] != 0,
                       !(L.margin[g] > kSeen), {}};
        for (std::size_t i = 0; i < L.cells.size(); ++i)
          if (L.group[i] == static_cast<Index>(g) && L.cells[i] != kExterior) sv.hexes.push_back(L.cells[i]);
        if (sv.id != v) sv.displacement = displacement(v, L, static_cast<Index>(g), sv.hexes);
        ids[g] = sv.id;
        s.vertices.push_back(std::move(sv));
      }
      for (Index k = iq_inc_.offsets[v]; k < iq_inc_.offsets[v + 1]; ++k) {
        const Index q = iq_inc_.ids[k];
        const int c = corner(iq_[q].v, v);
        s.outside_ids[q][c] = ids[L.group_of(iq_[q].outside_hex)];
        s.shrink_ids[q][c] = ids[L.group_of(iq_[q].shrink_hex)];
      }
    }
  }

  /// The hex to flip at a stuck vertex: the lowest-numbered hex of the side with fewer hexes
  /// there (the outside on a tie), which turns the pinch into a plain corner.
  Index flip_candidate(const Local& L) const {
    int shrink = 0, total = 0;
    for (Index c : L.cells)
      if (c != kExterior) shrink += in_[c] != 0, ++total;
    const bool flip_shrink = 2 * shrink < total;
    for (Index c : L.cells)
      if (c != kExterior && (in_[c] != 0) == flip_shrink) return c;
    return L.cells.front();
  }

  /// `offset` × the mean length of the group's interface edges at v, along its direction,
  /// lengthened at convex corners so that the layer is `offset` thick normal to each quad.
  Vec3 displacement(Index v, const Local& L, Index g, const std::vector<Index>& hexes) const {
    const Vec3 dir = L.dir[g];
    double length = 0, min_cos = 1;
    int edges = 0;
    for (Index k = iq_inc_.offsets[v]; k < iq_inc_.offsets[v + 1]; ++k) {
      const InterfaceQuad& q = iq_[iq_inc_.ids[k]];
      const bool s = L.group_of(q.shrink_hex) == g;
      if (!s && L.group_of(q.outside_hex) != g) continue;
      const int c = corner(q.v, v);
      for (int d : {1, 3}) {
        length += (m_.points[q.v[(c + d) % 4]] - m_.points[v]).norm();
        ++edges;
      }
      const Vec3 a = s ? Vec3(-area_vector(m_, q.v)) : area_vector(m_, q.v);
      if (a.norm() > 0) min_cos = std::min(min_cos, dir.dot(a.normalized()));
    }
    if (edges == 0) return Vec3::Zero();
    Vec3 d = dir * (opt_.offset * length / edges / std::max(min_cos, 0.5));
    // Where the group still has boundary quads at v, the interface ends on the boundary: the
    // vertex stays in the boundary's tangent plane so the sheet ends there too. (With
    // include_boundary, boundary quads of the shrink set are interface quads instead.)
    Vec3 boundary_normal = Vec3::Zero();
    if (!opt_.include_boundary)
      for (Index h : hexes)
        for (int f = 0; f < 6; ++f)
          if (nb_[h][f] < 0 && face_has(h, f, v)) {
            const auto& fc = kHexFaces[f];
            boundary_normal +=
                area_vector(m_, {m_.hexes[h][fc[0]], m_.hexes[h][fc[1]], m_.hexes[h][fc[2]], m_.hexes[h][fc[3]]});
          }
    if (boundary_normal.norm() > 0) {
      const Vec3 b = boundary_normal.normalized();
      d -= d.dot(b) * b;
    }
    return d;
  }

  /// As a vertex's displacement shrinks to zero, a new hex stays positive only if the
  /// displacement points to the group's side of each corner at v. On a curved or folded
  /// interface the mean normal may not, so tilt it toward the worst corner normal until every
  /// corner sees it (or keep the best found). `lo` receives the smallest cosine.
  static Vec3 visible_direction(const std::vector<Vec3>& corner_normals, Vec3 d, double& lo_out) {
    auto worst = [&](const Vec3& x, Vec3& n) {
      double lo = 2;
      for (const Vec3& c : corner_normals)
        if (x.dot(c) < lo) lo = x.dot(c), n = c;
      return lo;
    };
    constexpr double kEnough = 0.2;  // cos of 78°: comfortably positive corners
    Vec3 n = d, best = d;
    double best_lo = worst(d, n);
    // Subgradient ascent on min_i d·n_i with a decreasing step (a tiny LP; exactness is not
    // needed, only a direction with a positive margin where one exists).
    for (int it = 0; it < 400 && best_lo < kEnough; ++it) {
      d = (d + 0.2 / (1 + it / 20.0) * n).normalized();
      const double lo = worst(d, n);
      if (lo > best_lo) best_lo = lo, best = d;
    }
    lo_out = best_lo;
    return best;
  }

  const HexMesh& m_;
  const std::vector<std::uint8_t>& in_;
  const std::vector<std::array<Index, 6>>& nb_;
  const std::vector<InterfaceQuad>& iq_;
  const PillowOptions& opt_;
  const Incidence& hex_inc_;
  Incidence iq_inc_;
  std::vector<std::uint8_t> boundary_;
  std::vector<PinchedEdge> edges_;
  std::vector<std::pair<Index, Index>> at_;  // (vertex, pinched edge), sorted
  mutable std::map<std::pair<Index, std::uint64_t>, Local> memo_;
};

}  // namespace

InterfaceSplit split_interface(const HexMesh& mesh, const std::vector<std::uint8_t>& in,
                               const std::vector<std::array<Index, 6>>& nb, const std::vector<InterfaceQuad>& iq,
                               const PillowOptions& options, const Incidence& hex_inc) {
  return Splitter(mesh, in, nb, iq, options, hex_inc).run();
}

}  // namespace isohex::detail
