// The two sides of a cut: classification and its cleaning (see internal/cut_steps.hpp).
#include "isohex/sheets/internal/cut_steps.hpp"

#include <algorithm>
#include <cmath>

namespace isohex::internal {

std::vector<std::uint8_t> first_sides(const HexMesh& m, const std::vector<std::array<Index, 6>>& nb,
                                      const contour::LevelSet& surface, double tie_band) {
  std::vector<std::uint8_t> side(m.hexes.size());
  for (Index h = 0; h < m.num_hexes(); ++h) {
    Vec3 at = Vec3::Zero();
    int faces = 0;
    for (int f = 0; f < 6; ++f)
      if (nb[h][f] < 0) {
        for (Index v : face_vertices(m.hexes[h], f)) at += m.points[v];
        ++faces;
      }
    const Vec3 p = faces ? Vec3(at / (4.0 * faces)) : m.centroid(h);
    if (tie_band <= 0) {
      side[h] = surface.level(p) > 0;
      continue;
    }
    // Within tie_band × the hex's mean edge of the surface (|L| / |∇L|): outside.
    Vec3 g;
    const double l = surface.level(p, g);
    double size = 0;
    for (const auto& e : kHexEdges) size += (m.points[m.hexes[h][e[0]]] - m.points[m.hexes[h][e[1]]]).norm();
    side[h] = l > 0 && !(g.norm() > 0 && l / g.norm() <= tie_band * size / 12);
  }
  return side;
}

std::vector<EarlierFace> faces_on_earlier_cuts(const HexMesh& m, const std::vector<std::array<Index, 6>>& nb,
                                               const std::vector<Keeps>& keeps, int first_cut,
                                               const contour::LevelSet& surface) {
  std::vector<EarlierFace> out;
  for (Index h = 0; h < m.num_hexes(); ++h)
    for (int f = 0; f < 6; ++f) {
      const Index g = nb[h][f];
      if (g < h) continue;
      const Quad q = face_vertices(m.hexes[h], f);
      const bool on = std::any_of(keeps[q[0]].begin(), keeps[q[0]].end(), [&](const Keep& k) {
        return k.surface >= first_cut &&
               std::all_of(q.begin() + 1, q.end(), [&](Index v) { return on_surface(keeps[v], k.surface); });
      });
      if (!on) continue;
      Vec3 c = Vec3::Zero();
      for (Index v : q) c += m.points[v];
      out.push_back({h, g, static_cast<std::uint8_t>(surface.level(c / 4.0) > 0)});
    }
  return out;
}

void settle_sides(const HexMesh& m, const std::vector<std::array<Index, 6>>& nb, const std::vector<EarlierFace>& earlier,
                  const std::vector<std::uint8_t>& locked, std::vector<std::uint8_t>& side, std::size_t& moved) {
  for (int round = 0; round < 100; ++round) {
    bool changed = false;
    for (const EarlierFace& e : earlier)
      for (Index h : {e.h, e.g})
        if (side[h] != e.side && !locked[h]) side[h] = e.side, changed = true;
    // One hex at a time, in order: each flip takes at least two faces off the interface, so
    // this ends; flipping all at once would swap a checkerboard back and forth (a plane through
    // the middle of a layer of hexes, their centroids' signs mixed).
    std::size_t flips = 0;
    for (Index h = 0; h < m.num_hexes(); ++h) {
      if (locked[h]) continue;
      int across = 0;
      for (Index g : nb[h]) across += g >= 0 && side[g] != side[h];
      if (across >= 4) side[h] = !side[h], ++flips;
    }
    moved += flips;
    if (!changed && flips == 0) break;
  }
}

std::size_t unreachable_to_one_side(const HexMesh& m, const Incidence& inc, const std::vector<std::uint8_t>& side,
                                    const std::vector<Keeps>& keeps, int cut_id, const Placer& placer,
                                    std::vector<std::uint8_t>& next, std::vector<std::uint8_t>& locked) {
  const std::vector<contour::LevelSet>& levels = placer.levels;
  next = side;
  std::size_t bad = 0;
  for (Index v = 0; v < m.num_vertices(); ++v) {
    bool in = false, out = false;
    for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) (side[inc.ids[k]] ? in : out) = true;
    if (!(in && out)) continue;
    Keeps trial = keeps[v];
    trial.push_back({cut_id, Vec3::Zero()});
    Vec3 x = m.points[v];
    if (placer.place(x, trial)) continue;
    ++bad;
    // The side of its hexes locked before (a neighbour's), else of its own sign: the spot where
    // the cut only grazes the surface goes to one side as a whole.
    std::uint8_t to = levels[static_cast<std::size_t>(cut_id)].level(m.points[v]) > 0;
    for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k)
      if (locked[inc.ids[k]]) {
        to = next[inc.ids[k]];
        break;
      }
    for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k)
      if (!locked[inc.ids[k]]) next[inc.ids[k]] = to, locked[inc.ids[k]] = 1;
  }
  return bad;
}

namespace {

// Whether vertex v keeps to `keep` (a level set, or a face of the input's triangles facing alike).
bool keeps_to(const Keeps& v, const Keep& keep, double cos_limit) {
  return std::any_of(v.begin(), v.end(), [&](const Keep& y) {
    return keep.surface == y.surface && (keep.surface >= 0 || keep.facing.dot(y.facing) >= cos_limit);
  });
}

// Whether the edge a-b runs along a curve of two surfaces its ends share (a level set, or a
// face of the input's triangles facing alike, which counts as on): its midpoint is on both,
// within a quarter of the edge's length (|L| / |grad L|). Not an edge across a patch between
// two branches of the curve: the bottom of a plate thinner than a cell standing on a face of the
// box has both ends on the plate's skin and on the box face, its middle inside the plate; no cut point collapses such an edge, and its
// ends, sent to one side, would drag the next such edge with them along the whole plate
// (cthead h 4, the sagittal plane: 14 hexes flattened to SJ 0).
bool along_curve(const Vec3& a, const Vec3& b, const Keeps& ka, const Keeps& kb,
                 const std::vector<contour::LevelSet>& levels, double cos_limit) {
  const Vec3 mid = 0.5 * (a + b);
  const double reach = 0.25 * (b - a).norm();
  int on = 0;
  for (const Keep& k : ka) {
    if (!keeps_to(kb, k, cos_limit)) continue;
    if (k.surface < 0) {
      ++on;
      continue;
    }
    const contour::LevelSet& s = levels[static_cast<std::size_t>(k.surface)];
    Vec3 g;
    const double l = std::abs(s.level(mid, g));
    on += l <= 10 * s.tolerance() || l <= reach * g.norm();
  }
  return on >= 2;
}

}  // namespace

std::size_t doubled_curve_ends(const HexMesh& m, const std::vector<contour::LevelSet>& levels, const Incidence& inc,
                               const std::vector<std::array<Index, 2>>& edges, const std::vector<Keeps>& keeps,
                               double cos_limit, std::vector<std::uint8_t>& side, std::vector<std::uint8_t>& locked) {
  // For vertex v: the side its hexes would join and how many change; -1 if locked both ways
  // or already on one side.
  const auto plan = [&](Index v, std::uint8_t& to) {
    int count[2] = {0, 0}, held[2] = {0, 0};
    for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) {
      const Index h = inc.ids[k];
      ++count[side[h]];
      held[side[h]] += locked[h];
    }
    if (count[0] == 0 || count[1] == 0 || (held[0] && held[1])) return -1;
    to = held[1] ? 1 : held[0] ? 0 : count[1] > count[0];
    return count[!to];
  };
  std::size_t moved = 0;
  for (const auto& [a, b] : edges) {
    if (keeps[a].size() < 2 || keeps[b].size() < 2) continue;
    std::uint8_t to_a = 0, to_b = 0;
    const int na = plan(a, to_a), nb = plan(b, to_b);
    // Both ends on the interface first (counting hexes): the level sets only for those edges.
    if (na < 0 || nb < 0 || !along_curve(m.points[a], m.points[b], keeps[a], keeps[b], levels, cos_limit)) continue;
    const Index v = na <= nb ? a : b;
    const std::uint8_t to = na <= nb ? to_a : to_b;
    for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) side[inc.ids[k]] = to, locked[inc.ids[k]] = 1;
    ++moved;
  }
  return moved;
}

}  // namespace isohex::internal
