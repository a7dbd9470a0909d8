// Pillowing: split the interface, shrink the shrink set, connect with a new layer of hexes.
#include "isohex/sheets/pillow.hpp"

#include "isohex/error.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/mesh/validate.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/mesh/union_find.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace isohex {

namespace {

/// An interface quad, oriented counter-clockwise seen from outside its shrink-set hex (so its
/// normal points away from the shrink set).
struct InterfaceQuad {
  Quad v;
  Index shrink_hex;
};

/// A new vertex: the copy of `original` used by the shrink-set hexes of one fan.
struct Copy {
  Index original;
  Vec3 displacement;       // full displacement, before halving
  double scale = 1.0;      // halved while it inverts a hex
  std::vector<Index> hexes;  // the shrink-set hexes of the fan
};

/// Area vector of a quad (half the cross product of its diagonals).
Vec3 area_vector(const HexMesh& m, const Quad& q) {
  return 0.5 * (m.points[q[2]] - m.points[q[0]]).cross(m.points[q[3]] - m.points[q[1]]);
}

void require_valid(const HexMesh& mesh, const std::vector<std::uint8_t>& shrink_set) {
  if (shrink_set.size() != mesh.hexes.size())
    throw Error(fmt::format("pillow: the shrink set has {} flags but the mesh has {} hexes", shrink_set.size(),
                            mesh.hexes.size()));
  if (std::none_of(shrink_set.begin(), shrink_set.end(), [](std::uint8_t f) { return f != 0; }))
    throw Error("pillow: the shrink set is empty");
  const ValidationReport r = validate(mesh, {.max_messages = 1});
  if (!r.valid()) {
    std::string first = "unknown fault";
    for (const Fault& f : r.faults)
      if (is_error(f.kind)) {
        first = f.message;
        break;
      }
    throw Error(fmt::format("pillow: the input mesh is invalid ({} errors; first: {})", r.num_errors(), first));
  }
}

/// The interface quads (see pillow.hpp), in build_quads order.
std::vector<InterfaceQuad> find_interface(const std::vector<QuadFace>& quads, const std::vector<std::uint8_t>& in,
                                          bool include_boundary) {
  std::vector<InterfaceQuad> out;
  for (const QuadFace& q : quads) {
    const bool s0 = in[q.hex[0]] != 0;
    if (q.is_boundary()) {
      if (s0 && include_boundary) out.push_back({q.vertices, q.hex[0]});
      continue;
    }
    const bool s1 = in[q.hex[1]] != 0;
    if (s0 == s1) continue;
    if (s0) out.push_back({q.vertices, q.hex[0]});
    else out.push_back({{q.vertices[0], q.vertices[3], q.vertices[2], q.vertices[1]}, q.hex[1]});  // seen from hex[1]
  }
  return out;
}

/// Splits interface vertex v into one copy per fan of shrink-set hexes around it.
class VertexSplitter {
 public:
  VertexSplitter(const HexMesh& mesh, const std::vector<std::uint8_t>& in, const std::vector<std::array<Index, 6>>& nb,
                 const std::vector<InterfaceQuad>& iq, const Incidence& hex_inc, const Incidence& iq_inc,
                 const PillowOptions& opt)
      : m_(mesh), in_(in), nb_(nb), iq_(iq), hex_inc_(hex_inc), iq_inc_(iq_inc), opt_(opt) {}

  void split(Index v, std::vector<Copy>& copies) {
    std::vector<Index> hexes;
    for (Index k = hex_inc_.offsets[v]; k < hex_inc_.offsets[v + 1]; ++k)
      if (in_[hex_inc_.ids[k]]) hexes.push_back(hex_inc_.ids[k]);
    auto local = [&](Index h) { return static_cast<Index>(std::find(hexes.begin(), hexes.end(), h) - hexes.begin()); };
    // Fans: shrink-set hexes around v connected through shrink-set/shrink-set quads containing v.
    detail::UnionFind fans(hexes.size());
    for (Index h : hexes)
      for (int f = 0; f < 6; ++f) {
        const Index n = nb_[h][f];
        if (n >= 0 && in_[n] && face_has(h, f, v)) fans.unite(local(h), local(n));
      }
    std::vector<Index> roots;
    for (Index i = 0; i < static_cast<Index>(hexes.size()); ++i)
      if (fans.find(i) == i) roots.push_back(i);
    for (Index root : roots) {
      Copy c{v, Vec3::Zero(), 1.0, {}};
      for (Index i = 0; i < static_cast<Index>(hexes.size()); ++i)
        if (fans.find(i) == root) c.hexes.push_back(hexes[i]);
      std::vector<Index> fan;  // interface quads of this fan at v
      for (Index k = iq_inc_.offsets[v]; k < iq_inc_.offsets[v + 1]; ++k)
        if (std::find(c.hexes.begin(), c.hexes.end(), iq_[iq_inc_.ids[k]].shrink_hex) != c.hexes.end())
          fan.push_back(iq_inc_.ids[k]);
      if (fan.empty()) continue;  // this fan is not separated from anything at v: it keeps v
      require_one_piece(v, fan);
      c.displacement = displacement(v, c.hexes, fan);
      copies.push_back(std::move(c));
    }
  }

 private:
  bool face_has(Index h, int f, Index v) const {
    for (int c : kHexFaces[f])
      if (m_.hexes[h][c] == v) return true;
    return false;
  }

  /// The two neighbours of v along the quad's edges.
  static std::array<Index, 2> edge_ends(const Quad& q, Index v) {
    const int i = static_cast<int>(std::find(q.begin(), q.end(), v) - q.begin());
    return {q[(i + 1) % 4], q[(i + 3) % 4]};
  }

  /// A fan whose interface quads fall apart at v touches two separate outside regions there.
  void require_one_piece(Index v, const std::vector<Index>& fan) const {
    detail::UnionFind pieces(fan.size());
    for (std::size_t a = 0; a < fan.size(); ++a)
      for (std::size_t b = a + 1; b < fan.size(); ++b) {
        const auto ea = edge_ends(iq_[fan[a]].v, v), eb = edge_ends(iq_[fan[b]].v, v);
        for (Index x : ea)
          if (x == eb[0] || x == eb[1]) pieces.unite(static_cast<Index>(a), static_cast<Index>(b));
      }
    for (std::size_t a = 1; a < fan.size(); ++a)
      if (pieces.find(static_cast<Index>(a)) != pieces.find(0))
        throw Error(fmt::format(
            "pillow: the shrink set is pinched on the outside at vertex {}: its hexes there touch two separate "
            "regions outside the set, and one copy of the vertex cannot move away from both; add hex {} to the "
            "shrink set or remove the hexes around it",
            v, first_outside_hex(v)));
  }

  Index first_outside_hex(Index v) const {
    for (Index k = hex_inc_.offsets[v]; k < hex_inc_.offsets[v + 1]; ++k)
      if (!in_[hex_inc_.ids[k]]) return hex_inc_.ids[k];
    return -1;
  }

  Vec3 displacement(Index v, const std::vector<Index>& fan_hexes, const std::vector<Index>& fan) const {
    Vec3 normal = Vec3::Zero();  // into the shrink set
    double length = 0;
    int edges = 0;
    for (Index q : fan) {
      normal -= area_vector(m_, iq_[q].v);
      for (Index w : edge_ends(iq_[q].v, v)) {
        length += (m_.points[w] - m_.points[v]).norm();
        ++edges;
      }
    }
    if (!(normal.norm() > 0)) return Vec3::Zero();  // no direction: the check in pillow() reports it
    normal = visible_direction(v, fan, normal.normalized());
    // Lengthen at convex corners so that the layer is `offset` thick normal to every quad.
    double min_cos = 1;
    for (Index q : fan) {
      const Vec3 a = -area_vector(m_, iq_[q].v);
      if (a.norm() > 0) min_cos = std::min(min_cos, normal.dot(a.normalized()));
    }
    Vec3 d = normal * (opt_.offset * length / edges / std::max(min_cos, 0.5));
    // Where the fan still has boundary quads at v, the interface ends on the boundary: the
    // copy stays in the boundary's tangent plane so the sheet ends there too.
    Vec3 boundary_normal = Vec3::Zero();
    if (!opt_.include_boundary)
      for (Index h : fan_hexes)
        for (int f = 0; f < 6; ++f)
          if (nb_[h][f] < 0 && face_has(h, f, v)) {
            const auto& fc = kHexFaces[f];
            boundary_normal += area_vector(m_, {m_.hexes[h][fc[0]], m_.hexes[h][fc[1]], m_.hexes[h][fc[2]],
                                                m_.hexes[h][fc[3]]});
          }
    if (boundary_normal.norm() > 0) {
      const Vec3 b = boundary_normal.normalized();
      d -= d.dot(b) * b;
    }
    return d;
  }

  /// As a copy's displacement shrinks to zero, a new hex stays positive only if the
  /// displacement points to the shrink side of each fan quad's corner at v. On a curved or
  /// folded interface the mean normal may not, so tilt it toward the worst corner normal
  /// until every corner sees it (or keep the best found: the halving loop then reports it).
  Vec3 visible_direction(Index v, const std::vector<Index>& fan, Vec3 d) const {
    std::vector<Vec3> corner_normals;
    for (Index q : fan) {
      const auto [next, prev] = edge_ends(iq_[q].v, v);
      const Vec3 n = (m_.points[prev] - m_.points[v]).cross(m_.points[next] - m_.points[v]);  // into the shrink set
      if (n.norm() > 0) corner_normals.push_back(n.normalized());
    }
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
    if (!(best_lo > 0))
      throw Error(fmt::format(
          "pillow: the shrink set is pinched or folded at vertex {}: no direction from it into the shrink set "
          "sees all {} of its interface quads there, so no copy of it can be placed without inverting a new hex; "
          "add hex {} to the shrink set or remove the hexes around it",
          v, corner_normals.size(), first_outside_hex(v)));
    return best;
  }

  const HexMesh& m_;
  const std::vector<std::uint8_t>& in_;
  const std::vector<std::array<Index, 6>>& nb_;
  const std::vector<InterfaceQuad>& iq_;
  const Incidence& hex_inc_;
  const Incidence& iq_inc_;
  const PillowOptions& opt_;
};

bool positive(double sj) { return sj > 0 && !is_degenerate(sj); }

}  // namespace

PillowResult pillow(const HexMesh& mesh, const std::vector<std::uint8_t>& shrink_set, const PillowOptions& options) {
  if (!(options.offset > 0 && options.offset < 1))
    throw Error(fmt::format("pillow: offset must be in (0, 1), got {}", options.offset));
  require_valid(mesh, shrink_set);
  const std::vector<QuadFace> quads = build_quads(mesh);
  std::vector<std::array<Index, 6>> nb(mesh.hexes.size());
  for (const QuadFace& q : quads) {
    nb[q.hex[0]][q.local[0]] = q.hex[1];
    if (!q.is_boundary()) nb[q.hex[1]][q.local[1]] = q.hex[0];
  }
  const std::vector<InterfaceQuad> iq = find_interface(quads, shrink_set, options.include_boundary);
  if (iq.empty())
    throw Error(options.include_boundary
                    ? "pillow: the shrink set has no interface (no quad between it and the rest of the mesh, and "
                      "no boundary quad)"
                    : "pillow: the shrink set has no interface: it contains every hex of its part of the mesh "
                      "(pillow the boundary instead)");
  std::vector<Quad> iq_quads;
  iq_quads.reserve(iq.size());
  for (const auto& q : iq) iq_quads.push_back(q.v);
  const Incidence iq_inc = vertex_cells(iq_quads, mesh.num_vertices());
  const Incidence hex_inc = vertex_hexes(mesh);

  PillowResult r;
  std::vector<Copy> copies;
  VertexSplitter splitter(mesh, shrink_set, nb, iq, hex_inc, iq_inc, options);
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    if (iq_inc.count(v) > 0) {
      ++r.interface_vertices;
      splitter.split(v, copies);
    }
  r.interface_quads = iq.size();
  r.pinch_copies = copies.size() - r.interface_vertices;

  // Shrink: the fans' hexes take the copies.
  HexMesh& out = r.mesh;
  out = mesh;
  const Index nv0 = mesh.num_vertices(), nh0 = mesh.num_hexes();
  std::vector<Index> changed;
  for (std::size_t c = 0; c < copies.size(); ++c) {
    const Index id = nv0 + static_cast<Index>(c);
    out.points.push_back(mesh.points[copies[c].original] + copies[c].displacement);
    r.copy_of.push_back(copies[c].original);
    for (Index h : copies[c].hexes) {
      for (Index& x : out.hexes[h])
        if (x == copies[c].original) x = id;
      changed.push_back(h);
    }
  }
  std::sort(changed.begin(), changed.end());
  changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
  if (out.has_fixed()) out.fixed.resize(out.points.size(), 0);

  // Connect: one hex per interface quad. The quad faces away from the shrink set, so its
  // reverse is the bottom (0-1-2-3, facing into the new hex) and the copies are the top.
  out.hexes.reserve(mesh.hexes.size() + iq.size());  // keeps `after` below valid
  for (const InterfaceQuad& q : iq) {
    const Hex& before = mesh.hexes[q.shrink_hex];
    const Hex& after = out.hexes[q.shrink_hex];
    auto copy = [&](Index v) { return after[std::find(before.begin(), before.end(), v) - before.begin()]; };
    out.hexes.push_back({q.v[0], q.v[3], q.v[2], q.v[1], copy(q.v[0]), copy(q.v[3]), copy(q.v[2]), copy(q.v[1])});
    if (out.has_blocks()) out.blocks.push_back(mesh.blocks[q.shrink_hex]);
  }

  // Halve the displacements of copies used by inverted new or changed hexes until none is.
  std::vector<Index> checked = changed;
  for (Index h = nh0; h < out.num_hexes(); ++h) checked.push_back(h);
  std::vector<char> was_positive(checked.size(), 1);
  for (std::size_t i = 0; i < changed.size(); ++i) was_positive[i] = positive(scaled_jacobian(mesh.corners(changed[i])));
  std::vector<char> reduced(copies.size(), 0);
  for (int round = 0;; ++round) {
    std::vector<char> halve(copies.size(), 0);
    Index bad_hex = -1;
    for (std::size_t i = 0; i < checked.size(); ++i) {
      if (!was_positive[i] || positive(scaled_jacobian(out.corners(checked[i])))) continue;
      bad_hex = checked[i];
      for (Index x : out.hexes[checked[i]])
        if (x >= nv0) halve[x - nv0] = 1;
    }
    if (bad_hex < 0) break;
    if (round == options.max_halvings) {
      Index v = -1;
      for (Index x : out.hexes[bad_hex])
        if (x >= nv0) v = copies[x - nv0].original;
      throw Error(fmt::format("pillow: cannot place the copy of vertex {} without inverting {} hex {} (its "
                              "displacement was halved {} times); the shrink set is too thin or folded there",
                              v, bad_hex < nh0 ? "shrink-set" : "new", bad_hex, options.max_halvings));
    }
    for (std::size_t c = 0; c < copies.size(); ++c)
      if (halve[c]) {
        copies[c].scale *= 0.5;
        reduced[c] = 1;
        out.points[nv0 + c] = mesh.points[copies[c].original] + copies[c].scale * copies[c].displacement;
      }
  }
  r.reduced_vertices = static_cast<std::size_t>(std::count(reduced.begin(), reduced.end(), 1));
  r.min_new_scaled_jacobian = 1.0;
  for (Index h = nh0; h < out.num_hexes(); ++h)
    r.min_new_scaled_jacobian = std::min(r.min_new_scaled_jacobian, scaled_jacobian(out.corners(h)));
  return r;
}

PillowResult pillow_boundary(const HexMesh& mesh, Index block, double offset) {
  std::vector<std::uint8_t> in(mesh.hexes.size(), 1);
  if (block >= 0) {
    for (Index h = 0; h < mesh.num_hexes(); ++h) in[h] = mesh.block(h) == block;
    if (std::find(in.begin(), in.end(), 1) == in.end())
      throw Error(fmt::format("pillow: block {} has no hexes", block));
  }
  PillowOptions opt;
  opt.offset = offset;
  opt.include_boundary = true;
  return pillow(mesh, in, opt);
}

std::size_t count_multi_boundary_hexes(const HexMesh& mesh) {
  std::vector<std::uint8_t> faces(mesh.hexes.size(), 0);
  for (const QuadFace& q : build_quads(mesh))
    if (q.is_boundary()) ++faces[q.hex[0]];
  return static_cast<std::size_t>(std::count_if(faces.begin(), faces.end(), [](std::uint8_t n) { return n >= 2; }));
}

}  // namespace isohex
