// Conforming 3-refinement by transition templates on marked vertices (see refine.hpp).
#include "isohex/mesh/refine.hpp"

#include "isohex/error.hpp"
#include "isohex/mesh/topology.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <set>
#include <unordered_map>

namespace isohex {

namespace {

using P3 = std::array<int, 3>;
constexpr int kN = 6;  // lattice denominator per axis (sixths); weights are over kN^3 = 216

constexpr std::array<P3, 8> kCornerBits = {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                            {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};

int corner_of_bits(const P3& b) {
  for (int c = 0; c < 8; ++c)
    if (kCornerBits[c] == b) return c;
  return -1;
}

LatticeHex cube(int x, int y, int z, int s) {
  LatticeHex h;
  for (int c = 0; c < 8; ++c)
    h[c] = {x + s * kCornerBits[c][0], y + s * kCornerBits[c][1], z + s * kCornerBits[c][2]};
  return h;
}

// The canonical templates, in sixths. Corner: marked corner 0. Edge: corners 0, 1 (the edge
// along x at y = z = 0). Face: corners 0..3 (the face z = 0).

std::vector<LatticeHex> corner_template() {
  // The small cube at the corner; each of its three inner faces joined to the far parent face
  // it looks at. The three joins meet on the diagonal planes x = y, x = z, y = z.
  return {cube(0, 0, 0, 2),
          {{{2, 0, 0}, {6, 0, 0}, {6, 6, 0}, {2, 2, 0}, {2, 0, 2}, {6, 0, 6}, {6, 6, 6}, {2, 2, 2}}},
          {{{0, 2, 0}, {2, 2, 0}, {6, 6, 0}, {0, 6, 0}, {0, 2, 2}, {2, 2, 2}, {6, 6, 6}, {0, 6, 6}}},
          {{{0, 0, 2}, {2, 0, 2}, {2, 2, 2}, {0, 2, 2}, {0, 0, 6}, {6, 0, 6}, {6, 6, 6}, {0, 6, 6}}}};
}

// The 2D 3 -> 1 transition above a row of three small squares along the edge b = 0
// (coordinates (a, b), counter-clockwise): interior points at a = 1/3, 2/3, b = 2/3.
constexpr std::array<std::array<std::array<int, 2>, 4>, 4> kTransition2d = {{
    {{{0, 2}, {2, 2}, {2, 4}, {0, 6}}},
    {{{2, 2}, {4, 2}, {4, 4}, {2, 4}}},
    {{{4, 2}, {6, 2}, {6, 6}, {4, 4}}},
    {{{2, 4}, {4, 4}, {6, 6}, {0, 6}}}}};

std::vector<LatticeHex> edge_template() {
  // Three cubes along the edge; then the 2D transition of face z = 0 swept from z = 0 up to
  // the plane y = z, and that of face y = 0 swept from y = 0 to the same plane.
  std::vector<LatticeHex> t;
  for (int i = 0; i < 3; ++i) t.push_back(cube(2 * i, 0, 0, 2));
  for (const auto& q : kTransition2d) {
    LatticeHex h;
    for (int k = 0; k < 4; ++k) {
      h[k] = {q[k][0], q[k][1], 0};
      h[k + 4] = {q[k][0], q[k][1], q[k][1]};
    }
    t.push_back(h);
  }
  for (const auto& q : kTransition2d) {
    LatticeHex h;  // (a, b) -> (a, 0, b) is a reflection: traverse the quad backwards
    for (int k = 0; k < 4; ++k) {
      const auto& v = q[(4 - k) % 4];
      h[k] = {v[0], 0, v[1]};
      h[k + 4] = {v[0], v[1], v[1]};
    }
    t.push_back(h);
  }
  return t;
}

std::vector<LatticeHex> face_template() {
  // Nine cubes on the face, then the dual sheets above them: a horizontal layer of nine
  // hexes whose corner hexes rise to the parent's vertical edges; a U-shaped sheet in x
  // (roof at the lower level) crossing the middle sheet x = 1/2 in the three hexes of the
  // fourth row; and a U-shaped sheet in y (roof higher) whose crossing with y = 1/2 is the
  // last hex, which holds the unsplit opposite face. The four points inside the parent sit at
  // height 1/2 (the only points off the 1/3 lattice); on the lattice they would flatten the
  // hexes of the fourth row (min scaled Jacobian 0.316 at 1/2).
  std::vector<LatticeHex> t;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) t.push_back(cube(2 * i, 2 * j, 0, 2));
  const std::vector<LatticeHex> upper = {
      {{{0, 0, 2}, {2, 0, 2}, {2, 2, 2}, {0, 2, 2}, {0, 0, 6}, {2, 0, 4}, {2, 2, 3}, {0, 2, 4}}},
      {{{0, 2, 2}, {2, 2, 2}, {2, 4, 2}, {0, 4, 2}, {0, 2, 4}, {2, 2, 3}, {2, 4, 3}, {0, 4, 4}}},
      {{{0, 4, 2}, {2, 4, 2}, {2, 6, 2}, {0, 6, 2}, {0, 4, 4}, {2, 4, 3}, {2, 6, 4}, {0, 6, 6}}},
      {{{2, 0, 2}, {4, 0, 2}, {4, 2, 2}, {2, 2, 2}, {2, 0, 4}, {4, 0, 4}, {4, 2, 3}, {2, 2, 3}}},
      {{{2, 2, 2}, {4, 2, 2}, {4, 4, 2}, {2, 4, 2}, {2, 2, 3}, {4, 2, 3}, {4, 4, 3}, {2, 4, 3}}},
      {{{2, 4, 2}, {4, 4, 2}, {4, 6, 2}, {2, 6, 2}, {2, 4, 3}, {4, 4, 3}, {4, 6, 4}, {2, 6, 4}}},
      {{{4, 0, 2}, {6, 0, 2}, {6, 2, 2}, {4, 2, 2}, {4, 0, 4}, {6, 0, 6}, {6, 2, 4}, {4, 2, 3}}},
      {{{4, 2, 2}, {6, 2, 2}, {6, 4, 2}, {4, 4, 2}, {4, 2, 3}, {6, 2, 4}, {6, 4, 4}, {4, 4, 3}}},
      {{{4, 4, 2}, {6, 4, 2}, {6, 6, 2}, {4, 6, 2}, {4, 4, 3}, {6, 4, 4}, {6, 6, 6}, {4, 6, 4}}},
      {{{2, 0, 4}, {4, 0, 4}, {4, 2, 3}, {2, 2, 3}, {0, 0, 6}, {6, 0, 6}, {6, 2, 4}, {0, 2, 4}}},
      {{{2, 4, 3}, {4, 4, 3}, {4, 6, 4}, {2, 6, 4}, {0, 4, 4}, {6, 4, 4}, {6, 6, 6}, {0, 6, 6}}},
      {{{2, 2, 3}, {4, 2, 3}, {4, 4, 3}, {2, 4, 3}, {0, 2, 4}, {6, 2, 4}, {6, 4, 4}, {0, 4, 4}}},
      {{{0, 2, 4}, {6, 2, 4}, {6, 4, 4}, {0, 4, 4}, {0, 0, 6}, {6, 0, 6}, {6, 6, 6}, {0, 6, 6}}}};
  t.insert(t.end(), upper.begin(), upper.end());
  return t;
}

std::vector<LatticeHex> full_template() {
  std::vector<LatticeHex> t;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) t.push_back(cube(2 * i, 2 * j, 2 * k, 2));
  return t;
}

/// A cube symmetry: output axis i takes input axis perm[i], flipped if flip[i].
struct Symmetry {
  std::array<int, 3> perm;
  std::array<bool, 3> flip;
  bool reflects;
  [[nodiscard]] P3 apply(const P3& p, int n) const {
    P3 q;
    for (int i = 0; i < 3; ++i) q[i] = flip[i] ? n - p[perm[i]] : p[perm[i]];
    return q;
  }
  [[nodiscard]] std::uint8_t apply_mask(std::uint8_t m) const {
    std::uint8_t r = 0;
    for (int c = 0; c < 8; ++c)
      if (m >> c & 1) r |= static_cast<std::uint8_t>(1u << corner_of_bits(apply(kCornerBits[c], 1)));
    return r;
  }
};

std::vector<Symmetry> cube_symmetries() {
  std::vector<Symmetry> s;
  std::array<int, 3> perm = {0, 1, 2};
  do {
    const bool odd = (perm[0] > perm[1]) + (perm[0] > perm[2]) + (perm[1] > perm[2]) == 1 ||
                     (perm[0] > perm[1]) + (perm[0] > perm[2]) + (perm[1] > perm[2]) == 3;
    for (int f = 0; f < 8; ++f) {
      const std::array<bool, 3> flip = {(f & 1) != 0, (f & 2) != 0, (f & 4) != 0};
      s.push_back({perm, flip, odd != (std::popcount(static_cast<unsigned>(f)) % 2 == 1)});
    }
  } while (std::next_permutation(perm.begin(), perm.end()));
  return s;
}

std::uint8_t face_mask(int f) {
  std::uint8_t m = 0;
  for (int c : kHexFaces[f]) m |= static_cast<std::uint8_t>(1u << c);
  return m;
}

bool is_edge_mask(std::uint8_t m) {
  for (const auto& e : kHexEdges)
    if (m == ((1u << e[0]) | (1u << e[1]))) return true;
  return false;
}

struct Tables {
  std::array<std::uint8_t, 256> promoted{};
  std::array<RefineTemplate, 256> kind{};
  std::array<std::vector<LatticeHex>, 256> hexes;
};

const Tables& tables() {
  static const Tables t = [] {
    Tables t;
    for (int m = 0; m < 256; ++m) {
      const auto mask = static_cast<std::uint8_t>(m);
      const int n = std::popcount(static_cast<unsigned>(m));
      std::uint8_t p = 0xff;
      if (n <= 1 || (n == 2 && is_edge_mask(mask))) {
        p = mask;
      } else {
        for (int f = 0; f < 6; ++f)
          if ((mask & face_mask(f)) == mask) p = face_mask(f);  // at most one face holds 2 diagonal / 3
      }
      t.promoted[m] = p;
    }
    const std::vector<Symmetry> syms = cube_symmetries();
    const std::array<std::pair<RefineTemplate, std::uint8_t>, 4> canon = {
        {{RefineTemplate::corner, 0x01}, {RefineTemplate::edge, 0x03}, {RefineTemplate::face, 0x0f},
         {RefineTemplate::full, 0xff}}};
    const std::array<std::vector<LatticeHex>, 4> base = {corner_template(), edge_template(), face_template(),
                                                         full_template()};
    t.kind[0] = RefineTemplate::keep;
    t.hexes[0] = {cube(0, 0, 0, kN)};
    for (int m = 1; m < 256; ++m) {
      if (t.promoted[m] != m) continue;
      const auto mask = static_cast<std::uint8_t>(m);
      for (std::size_t k = 0; k < canon.size() && t.hexes[m].empty(); ++k)
        for (const Symmetry& s : syms) {
          if (s.apply_mask(canon[k].second) != mask) continue;
          t.kind[m] = canon[k].first;
          for (const LatticeHex& h : base[k]) {
            LatticeHex q;
            for (int c = 0; c < 8; ++c) q[c] = s.apply(h[c], kN);
            // A reflection mirrors every sub-hex: walk both quads the other way round.
            if (s.reflects) q = {q[0], q[3], q[2], q[1], q[4], q[7], q[6], q[5]};
            t.hexes[m].push_back(q);
          }
          break;
        }
    }
    return t;
  }();
  return t;
}

/// Canonical key of a lattice point of a hex: (vertex id, weight over 216), sorted by id.
struct Key {
  std::array<std::pair<Index, int>, 8> w{};
  int n = 0;
  bool operator==(const Key& o) const {
    return n == o.n && std::equal(w.begin(), w.begin() + n, o.w.begin());
  }
};
struct KeyHash {
  std::size_t operator()(const Key& k) const {
    std::size_t h = static_cast<std::size_t>(k.n);
    for (int i = 0; i < k.n; ++i)
      h = (h ^ (static_cast<std::size_t>(k.w[i].first) * 0x9E3779B97F4A7C15ULL + static_cast<std::size_t>(k.w[i].second))) *
          0x100000001B3ULL;
    return h;
  }
};

Key key_of(const Hex& hex, const P3& p) {
  Key k;
  for (int c = 0; c < 8; ++c) {
    int w = 1;
    for (int a = 0; a < 3; ++a) w *= kCornerBits[c][a] ? p[a] : kN - p[a];
    if (w != 0) k.w[k.n++] = {hex[c], w};
  }
  std::sort(k.w.begin(), k.w.begin() + k.n);
  int m = 0;  // merge repeated ids (a degenerate hex), so the key stays canonical
  for (int i = 0; i < k.n; ++i) {
    if (m > 0 && k.w[m - 1].first == k.w[i].first) k.w[m - 1].second += k.w[i].second;
    else k.w[m++] = k.w[i];
  }
  k.n = m;
  return k;
}

// Bit c set when corner c of the hex is marked.
std::uint8_t corner_mask(const Hex& h, const std::vector<std::uint8_t>& marked) {
  std::uint8_t m = 0;
  for (int c = 0; c < 8; ++c) m |= static_cast<std::uint8_t>(marked[h[c]] << c);
  return m;
}

}  // namespace

const char* refine_template_name(RefineTemplate t) {
  switch (t) {
    case RefineTemplate::keep: return "unrefined";
    case RefineTemplate::corner: return "corner";
    case RefineTemplate::edge: return "edge";
    case RefineTemplate::face: return "face";
    case RefineTemplate::full: return "full";
  }
  return "?";
}

std::uint8_t promoted_mask(std::uint8_t corner_mask) { return tables().promoted[corner_mask]; }

std::size_t close_marks(const HexMesh& mesh, const Incidence& around, std::vector<std::uint8_t>& marked,
                        std::vector<Index> seeds, std::size_t limit) {
  const Tables& tab = tables();
  std::vector<Index> added;
  while (!seeds.empty()) {
    const Index v = seeds.back();
    seeds.pop_back();
    for (Index k = around.offsets[v]; k < around.offsets[v + 1]; ++k) {
      const Hex& hx = mesh.hexes[around.ids[k]];
      const std::uint8_t m = corner_mask(hx, marked), p = tab.promoted[m];
      for (int c = 0; c < 8; ++c) {
        if (!(p >> c & 1) || (m >> c & 1)) continue;
        marked[hx[c]] = 1;
        added.push_back(hx[c]);
        seeds.push_back(hx[c]);
        if (added.size() > limit) {
          for (Index a : added) marked[a] = 0;
          return limit + 1;
        }
      }
    }
  }
  return added.size();
}

RefineTemplate template_of(std::uint8_t corner_mask) {
  if (promoted_mask(corner_mask) != corner_mask)
    throw Error(fmt::format("refine: corner mask {:#04x} is not a template configuration", corner_mask));
  return tables().kind[corner_mask];
}

const std::vector<LatticeHex>& template_hexes(std::uint8_t corner_mask) {
  template_of(corner_mask);  // throws for a configuration that needs promotion
  return tables().hexes[corner_mask];
}

std::vector<std::uint8_t> marked_vertices_of(const HexMesh& mesh, const std::vector<Index>& hex_ids) {
  std::vector<std::uint8_t> marked(mesh.points.size(), 0);
  for (Index h : hex_ids) {
    if (h < 0 || h >= mesh.num_hexes())
      throw Error(fmt::format("refine: hex id {} is out of range [0, {})", h, mesh.num_hexes()));
    for (Index v : mesh.hexes[h]) marked[v] = 1;
  }
  return marked;
}

RefineResult refine(const HexMesh& mesh, std::vector<std::uint8_t> marked) {
  if (marked.size() != mesh.points.size())
    throw Error(fmt::format("refine: {} vertex marks for {} vertices", marked.size(), mesh.points.size()));
  const Tables& tab = tables();
  RefineResult r;
  for (auto& f : marked) f = f != 0;
  r.marked_vertices = static_cast<std::size_t>(std::count(marked.begin(), marked.end(), 1));

  std::vector<Index> seeds;
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    if (marked[v]) seeds.push_back(v);
  r.promoted_vertices = close_marks(mesh, vertex_hexes(mesh), marked, std::move(seeds));
  auto mask_of = [&](const Hex& h) { return corner_mask(h, marked); };

  // Boundary edges and quads, to decide which new vertices inherit a fixed flag.
  std::set<std::array<Index, 4>> fixed_quads;
  std::set<std::array<Index, 2>> fixed_edges;
  if (mesh.has_fixed()) {
    for (Quad q : boundary_quads(mesh)) {
      if (!std::all_of(q.begin(), q.end(), [&](Index v) { return mesh.fixed[v] != 0; })) continue;
      for (int i = 0; i < 4; ++i) fixed_edges.insert({std::min(q[i], q[(i + 1) % 4]), std::max(q[i], q[(i + 1) % 4])});
      std::sort(q.begin(), q.end());
      fixed_quads.insert(q);
    }
  }

  HexMesh& out = r.mesh;
  out.points = mesh.points;
  if (mesh.has_fixed()) out.fixed = mesh.fixed;
  std::unordered_map<Key, Index, KeyHash> ids;
  auto vertex = [&](const Hex& hex, const P3& p) -> Index {
    const Key k = key_of(hex, p);
    if (k.n == 1) return k.w[0].first;
    const auto [it, inserted] = ids.try_emplace(k, out.num_vertices());
    if (!inserted) return it->second;
    Vec3 x = Vec3::Zero();  // in sorted-id order, so every hex computes the same bits
    for (int i = 0; i < k.n; ++i) x += static_cast<double>(k.w[i].second) * mesh.points[k.w[i].first];
    out.points.push_back(x / static_cast<double>(kN * kN * kN));
    for (int i = 0; i < k.n; ++i) r.source_ids.push_back(k.w[i].first);
    r.source_offsets.push_back(static_cast<Index>(r.source_ids.size()));
    if (mesh.has_fixed()) {
      bool fixed = false;
      if (k.n == 2) fixed = fixed_edges.count({k.w[0].first, k.w[1].first}) != 0;
      if (k.n == 4) fixed = fixed_quads.count({k.w[0].first, k.w[1].first, k.w[2].first, k.w[3].first}) != 0;
      out.fixed.push_back(fixed ? 1 : 0);
    }
    return it->second;
  };
  for (Index h = 0; h < mesh.num_hexes(); ++h) {
    const Hex& hex = mesh.hexes[h];
    const std::uint8_t m = mask_of(hex);
    const RefineTemplate kind = tab.kind[m];
    ++r.parents[static_cast<int>(kind)];
    if (kind == RefineTemplate::keep) {
      out.hexes.push_back(hex);
    } else {
      for (const LatticeHex& lh : tab.hexes[m]) {
        Hex child;
        for (int c = 0; c < 8; ++c) child[c] = vertex(hex, lh[c]);
        out.hexes.push_back(child);
      }
    }
    const std::size_t added = out.hexes.size() - r.parent_hex.size();
    r.children[static_cast<int>(kind)] += added;
    r.parent_hex.insert(r.parent_hex.end(), added, h);
    if (mesh.has_blocks()) out.blocks.insert(out.blocks.end(), added, mesh.blocks[h]);
  }
  r.marked = std::move(marked);
  return r;
}

}  // namespace isohex
