// Upper bounds of the scaled Jacobian that the fixed vertices impose (find_quality_bounds()).
#include "isohex/optimize/feasibility.hpp"
#include "isohex/optimize/local_energy.hpp"
#include "isohex/optimize/optimize.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace isohex {

namespace {

// The point of the convex hull of `n` nearest to the origin, by the faces it can lie on (a
// vertex, an edge, a triangle: Carathéodory in 3-D): the nearest point of each face's affine
// hull that lies in the face and that no point of the set undercuts (p · n_i >= |p|² for all i,
// the optimality condition). Zero when the origin is inside. The sets are a handful of frames.
Vec3 nearest_in_hull(const std::vector<Vec3>& n) {
  const std::size_t m = n.size();
  const auto optimal = [&](const Vec3& p) {
    const double p2 = p.squaredNorm();
    for (const Vec3& q : n)
      if (p.dot(q) < p2 * (1 - 1e-12)) return false;
    return true;
  };
  for (std::size_t i = 0; i < m; ++i)
    if (optimal(n[i])) return n[i];
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t j = i + 1; j < m; ++j) {
      const Vec3 d = n[j] - n[i];
      const double t = -n[i].dot(d) / d.squaredNorm();
      if (t > 0 && t < 1 && optimal(n[i] + t * d)) return n[i] + t * d;
    }
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t j = i + 1; j < m; ++j)
      for (std::size_t k = j + 1; k < m; ++k) {
        // p = n_i + s d1 + t d2 with p ⟂ d1, d2.
        const Vec3 d1 = n[j] - n[i], d2 = n[k] - n[i];
        Eigen::Matrix2d G;
        G << d1.dot(d1), d1.dot(d2), d1.dot(d2), d2.dot(d2);
        const Eigen::Vector2d st = G.fullPivLu().solve(Eigen::Vector2d(-n[i].dot(d1), -n[i].dot(d2)));
        if (!(st[0] > 0 && st[1] > 0 && st[0] + st[1] < 1)) continue;
        const Vec3 p = n[i] + st[0] * d1 + st[1] * d2;
        if (optimal(p)) return p;
      }
  return Vec3::Zero();
}


}  // namespace

const char* to_string(QualityBound::Kind kind) {
  return kind == QualityBound::Kind::fixed_frame ? "fixed_frame" : "edge_direction";
}

std::vector<QualityBound> find_quality_bounds(const HexMesh& mesh, const std::vector<std::uint8_t>& fixed,
                                              double level) {
  std::vector<QualityBound> out;
  if (fixed.empty()) return out;
  // (fixed corner, free vertex) -> the frames' n_i and their hexes, in hex order.
  std::map<std::pair<Index, Index>, std::pair<std::vector<Vec3>, std::vector<Index>>> edges;
  for (Index h = 0; h < mesh.num_hexes(); ++h) {
    const Hex& hx = mesh.hexes[h];
    const auto p = mesh.corners(h);
    if (std::all_of(hx.begin(), hx.end(), [&](Index v) { return fixed[v] != 0; }))
      if (const double v = opt::scaled_frame_value(p, opt::kCentreFrame); v < level)
        out.push_back({QualityBound::Kind::fixed_frame, -1, -1, v, {h}});
    for (int k = 0; k < 8; ++k) {
      if (!fixed[hx[k]]) continue;
      const auto& nb = kCornerNeighbors[k];
      int free_at = -1, free_count = 0;
      for (int j = 0; j < 3; ++j)
        if (!fixed[hx[nb[j]]]) free_at = j, ++free_count;
      const Vec3 e[3] = {p[nb[0]] - p[k], p[nb[1]] - p[k], p[nb[2]] - p[k]};
      if (free_count == 0) {
        if (const double v = opt::scaled_frame_value(p, k); v < level)
          out.push_back({QualityBound::Kind::fixed_frame, hx[k], -1, v, {h}});
      } else if (free_count == 1) {
        // det[e0 e1 e2] = e_j · (e_{j+1} × e_{j+2}): the free edge's direction against the
        // normal of the two fixed ones, scaled by the sine of their angle.
        const Vec3& a = e[(free_at + 1) % 3];
        const Vec3& b = e[(free_at + 2) % 3];
        auto& entry = edges[{hx[k], hx[nb[free_at]]}];
        entry.first.push_back(a.cross(b) / (a.norm() * b.norm()));
        entry.second.push_back(h);
      }
    }
  }
  std::sort(out.begin(), out.end(), [](const QualityBound& x, const QualityBound& y) {
    return std::make_pair(x.vertex, x.hexes[0]) < std::make_pair(y.vertex, y.hexes[0]);
  });
  for (auto& [key, entry] : edges) {
    const double bound = nearest_in_hull(entry.first).norm();
    if (!(bound < level)) continue;
    std::vector<Index> hexes = entry.second;
    std::sort(hexes.begin(), hexes.end());
    out.push_back({QualityBound::Kind::edge_direction, key.first, key.second, bound, std::move(hexes)});
  }
  return out;
}

}  // namespace isohex
