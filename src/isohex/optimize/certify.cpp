// Proofs that the fixed vertices leave no valid placement for some hexes, and the choice of
// the hexes the untangler gives up so that it can untangle everything else.
#include "isohex/optimize/feasibility.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/quality/hex_quality.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace isohex {

namespace {

// Below this inscribed-ball radius (in edge lengths) the half-spaces count as having no common
// interior point: what is left is at best a flat sliver where the frames are 0 (a degenerate
// hex), e.g. the apex of the cone of a fixed vertex whose fixed edges allow no inward direction.
constexpr double kEmptyRadius = 1e-9;
constexpr double kInfinite = 1e300;

// The radius (in edge lengths, within `box` edge lengths of the vertex) of the largest ball in
// which the frames f, affine in one vertex's displacement, are all positive; <= 0: none.
// `infinite` if no frame constrains (nothing to prove).
double cone_radius(const std::vector<opt::Affine>& f, double len, double box) {
  if (f.empty()) return kInfinite;
  std::vector<double> w(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) {
    w[i] = f[i].a.norm() * len;
    // A frame that the vertex cannot change at all (its fixed edges are parallel) is a proof
    // on its own when it is not positive.
    if (!(w[i] > 0)) {
      if (!(f[i].b > 0)) return -1;
      w[i] = 1;
    }
  }
  const opt::MaxMin r = opt::max_min_affine(f, w, box * len);
  return r.ok ? r.s : kInfinite;
}

// True when the frames f have no common positive point (100 edge lengths stand for "anywhere").
bool cone_empty(const std::vector<opt::Affine>& f, double len) {
  bool all_positive = true;
  for (const opt::Affine& a : f) all_positive = all_positive && a.b > 0;
  if (all_positive) return false;  // the vertex's current place is valid for these frames
  return cone_radius(f, len, 100) <= kEmptyRadius;
}

bool frame_all_fixed(const Hex& hx, int t, const std::vector<std::uint8_t>& fixed) {
  if (t == opt::kCentreFrame) return std::all_of(hx.begin(), hx.end(), [&](Index v) { return fixed[v] != 0; });
  bool all = fixed[hx[t]] != 0;
  for (int j : kCornerNeighbors[t]) all = all && fixed[hx[j]];
  return all;
}

}  // namespace

const char* to_string(InfeasibleSet::Kind kind) {
  return kind == InfeasibleSet::Kind::fixed_frame ? "fixed_frame" : "vertex_cone";
}

std::vector<InfeasibleSet> find_infeasible(const HexMesh& mesh, const std::vector<std::uint8_t>& fixed) {
  std::vector<InfeasibleSet> out;
  // Nothing fixed, nothing proven (the mask of a sliding boundary often pins no vertex): the
  // incidence and edge lengths below cost a third of a second on cthead h 2.
  if (std::none_of(fixed.begin(), fixed.end(), [](std::uint8_t f) { return f != 0; })) return out;
  for (Index h = 0; h < mesh.num_hexes(); ++h) {
    const auto p = mesh.corners(h);
    // Verdict calls a hex degenerate when an edge of a frame has squared length <= 2.22e-15
    // times its bounding-box diagonal squared; that diagonal is at least the largest distance
    // between two fixed vertices of the hex, so an edge of fixed vertices that short relative
    // to that distance stays degenerate wherever the free vertices go.
    double span2 = 0;
    for (int i = 0; i < 8; ++i)
      for (int j = i + 1; j < 8; ++j)
        if (fixed[mesh.hexes[h][i]] && fixed[mesh.hexes[h][j]]) span2 = std::max(span2, (p[i] - p[j]).squaredNorm());
    const Hex& hx = mesh.hexes[h];
    // An edge of two fixed vertices: the corner frames at its ends contain it.
    Index collapsed = -1;
    for (const auto& e : kHexEdges)
      if (collapsed < 0 && fixed[hx[e[0]]] && fixed[hx[e[1]]] &&
          (p[e[0]] - p[e[1]]).squaredNorm() <= 2.2204460492503131e-15 * span2)
        collapsed = hx[e[0]];
    if (collapsed >= 0) {
      out.push_back({InfeasibleSet::Kind::fixed_frame, collapsed, {h}});
      continue;
    }
    for (int t = 0; t < opt::kFrames; ++t) {
      if (!frame_all_fixed(hx, t, fixed) || opt::frame(p, t, 1.0).determinant() > 0) continue;
      out.push_back({InfeasibleSet::Kind::fixed_frame, t < 8 ? mesh.hexes[h][t] : -1, {h}});
      break;
    }
  }
  const Incidence inc = vertex_hexes(mesh);
  const std::vector<double> inv_len = opt::inverse_edge_lengths(mesh);
  std::vector<std::vector<Index>> cone(mesh.points.size());
  tbb::parallel_for(tbb::blocked_range<Index>(0, mesh.num_vertices()), [&](const auto& r) {
    for (Index v = r.begin(); v != r.end(); ++v) {
      if (fixed[v] || inc.count(v) == 0) continue;
      std::vector<Index> hex_of;
      const std::vector<opt::Affine> f = opt::vertex_frames(mesh, inc, inv_len, v, &fixed, nullptr, &hex_of);
      if (!cone_empty(f, opt::mean_edge_at(mesh, inc, v))) continue;
      std::sort(hex_of.begin(), hex_of.end());
      hex_of.erase(std::unique(hex_of.begin(), hex_of.end()), hex_of.end());
      cone[v] = std::move(hex_of);
    }
  });
  for (Index v = 0; v < mesh.num_vertices(); ++v)
    if (!cone[v].empty()) out.push_back({InfeasibleSet::Kind::vertex_cone, v, std::move(cone[v])});
  return out;
}

namespace opt {

std::vector<std::uint8_t> give_up(const HexMesh& mesh, const std::vector<std::uint8_t>& fixed,
                                  const std::vector<InfeasibleSet>& sets) {
  std::vector<std::uint8_t> skip(mesh.hexes.size(), 0);
  if (sets.empty()) return skip;
  const Incidence inc = vertex_hexes(mesh);
  const std::vector<double> inv_len = inverse_edge_lengths(mesh);
  for (const InfeasibleSet& s : sets)
    if (s.kind == InfeasibleSet::Kind::fixed_frame) skip[s.hexes[0]] = 1;
  const auto open = [&](const InfeasibleSet& s) {
    return !cone_empty(vertex_frames(mesh, inc, inv_len, s.vertex, &fixed, &skip), mean_edge_at(mesh, inc, s.vertex));
  };
  // Greedy: for each proof not yet answered, give up the hex of its set whose removal leaves
  // the vertex the widest place near where it is (the inscribed radius within one edge
  // length), then the one answering the most open proofs at once (proofs overlap where fixed
  // vertices with no inward direction are neighbours), then the first in id order; repeated
  // until the vertex's remaining frames with fixed vertices admit a valid place. The widest
  // place first, because the frames of the vertex's other hexes must fit into it as well: on
  // ECR armadillo_in, preferring the most answers left one more hex stuck near 0.
  for (const InfeasibleSet& s : sets) {
    if (s.kind != InfeasibleSet::Kind::vertex_cone) continue;
    const double len = mean_edge_at(mesh, inc, s.vertex);
    while (!open(s)) {
      std::vector<const InfeasibleSet*> closed;
      for (const InfeasibleSet& t : sets)
        if (t.kind == InfeasibleSet::Kind::vertex_cone && !open(t)) closed.push_back(&t);
      Index pick = -1;
      int pick_answers = -1;
      double pick_radius = 0;
      for (Index h : s.hexes) {
        if (skip[h]) continue;
        skip[h] = 1;
        int answers = 0;
        for (const InfeasibleSet* t : closed) answers += open(*t);
        const double radius = cone_radius(vertex_frames(mesh, inc, inv_len, s.vertex, &fixed, &skip), len, 1);
        skip[h] = 0;
        if (radius > pick_radius || (radius == pick_radius && answers > pick_answers) || pick < 0) {
          pick = h;
          pick_answers = answers;
          pick_radius = radius;
        }
      }
      if (pick < 0) break;
      skip[pick] = 1;
    }
  }
  return skip;
}

}  // namespace opt

}  // namespace isohex
