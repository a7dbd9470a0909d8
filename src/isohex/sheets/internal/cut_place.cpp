// Placement of cut vertices onto what they keep to (see internal/cut_steps.hpp).
#include "isohex/sheets/internal/cut_steps.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace isohex::internal {

std::vector<Keeps> boundary_keeps(const HexMesh& mesh, const std::vector<contour::LevelSet>& surfaces,
                                  double feature_degrees) {
  std::vector<Keeps> keeps(mesh.points.size());
  std::vector<std::uint8_t> on_level(mesh.points.size(), 0);
  const double cos_limit = std::cos(feature_degrees * std::numbers::pi / 180.0);
  const std::vector<Quad> quads = boundary_quads(mesh);
  for (const Quad& q : quads)
    for (Index v : q) {
      if (on_level[v]) continue;
      on_level[v] = 2;  // seen, on none
      for (std::size_t k = 0; k < surfaces.size(); ++k)
        if (surfaces[k].on(mesh.points[v])) keeps[v].push_back({static_cast<int>(k), Vec3::Zero()}), on_level[v] = 1;
    }
  for (const Quad& q : quads) {
    Vec3 n = (mesh.points[q[2]] - mesh.points[q[0]]).cross(mesh.points[q[3]] - mesh.points[q[1]]);
    if (!(n.norm() > 0)) continue;
    n.normalize();
    for (Index v : q) {
      if (on_level[v] == 1) continue;
      Keeps& k = keeps[v];
      if (std::none_of(k.begin(), k.end(), [&](const Keep& e) { return e.facing.dot(n) >= cos_limit; }))
        k.push_back({-1, n});
    }
  }
  return keeps;
}

bool Placer::by_turns(Vec3& x, const Keeps& keeps) const {
  Vec3 q = x;
  for (int round = 0; round < 1000; ++round) {
    bool done = true;
    for (const Keep& k : keeps) {
      if (k.surface >= 0) {
        const contour::LevelSet& s = levels[static_cast<std::size_t>(k.surface)];
        done = done && std::abs(s.level(q)) <= s.tolerance();
      } else {
        done = done && (tris.project(q, &k.facing) - q).norm() <= tri_tol;
      }
    }
    if (done) {
      if (!((q - x).norm() <= reach)) return false;
      x = q;
      return true;
    }
    for (const Keep& k : keeps) {
      if (k.surface >= 0) {
        if (!levels[static_cast<std::size_t>(k.surface)].project(q, reach)) return false;
      } else {
        q = tris.project(q, &k.facing);
      }
    }
    if (!((q - x).norm() <= 2 * reach)) return false;
  }
  return false;
}

bool Placer::place(Vec3& x, const Keeps& keeps) const {
  Vec3 y = x;
  if (!place_anywhere(y, keeps) || (domain && !domain->contains(y, 1e-9 * (domain->hi - domain->lo).norm())))
    return false;
  x = y;
  return true;
}

bool Placer::place_anywhere(Vec3& x, const Keeps& keeps) const {
  if (newton(x, keeps)) return true;
  if (keeps.size() <= 3 && by_turns(x, keeps)) return true;
  for (const Keep& k : keeps) {
    if (k.surface < 0 || !levels[static_cast<std::size_t>(k.surface)].field()) continue;
    Vec3 y = x;
    const contour::LevelSet& s = levels[static_cast<std::size_t>(k.surface)];
    if (s.bracket(y, 4 * step) && (newton(y, keeps) || (keeps.size() <= 3 && by_turns(y, keeps))) &&
        (y - x).norm() <= reach) {
      x = y;
      return true;
    }
  }
  return false;
}

bool Placer::newton(Vec3& x, const Keeps& keeps) const {
  const std::size_t k = std::min<std::size_t>(keeps.size(), 3);
  if (k == 0) return true;
  Vec3 q = x;
  for (int it = 0; it < 100; ++it) {
    Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
    Vec3 r = Vec3::Zero();
    bool done = true;
    for (std::size_t i = 0; i < k; ++i) {
      Vec3 g;
      double tol = tri_tol;
      if (keeps[i].surface >= 0) {
        const contour::LevelSet& s = levels[static_cast<std::size_t>(keeps[i].surface)];
        r[i] = s.level(q, g);
        tol = s.tolerance();
      } else {
        const Vec3 foot = tris.project(q, &keeps[i].facing, &g);
        r[i] = g.dot(q - foot);
      }
      J.row(i) = g.transpose();
      done = done && std::abs(r[i]) <= tol;
    }
    if (done) {
      if (!((q - x).norm() <= reach)) return false;
      x = q;
      return true;
    }
    // The least-norm solution of J d = r over the k rows: d = Jᵀ (J Jᵀ)⁻¹ r.
    const Eigen::MatrixXd Jk = J.topRows(static_cast<Eigen::Index>(k));
    const Eigen::MatrixXd M = Jk * Jk.transpose();
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(M);
    if (ldlt.info() != Eigen::Success || !(std::abs(M.determinant()) > 1e-12 * std::pow(M.trace() / static_cast<double>(k), static_cast<double>(k))))
      return false;  // the surfaces are tangent there: no single point or curve to go to
    const Eigen::VectorXd lambda = ldlt.solve(r.head(static_cast<Eigen::Index>(k)));
    q -= Jk.transpose() * lambda;
    if (!q.allFinite() || !((q - x).norm() <= 2 * reach)) return false;
  }
  return false;
}

BoundarySurface::Constraint constraint_of(const Keeps& k) {
  BoundarySurface::Constraint c;
  if (k.empty()) return c;
  const auto id = [](const Keep& e) { return e.surface >= 0 ? static_cast<std::int8_t>(e.surface) : BoundarySurface::kTriangles; };
  if (k.size() <= 2) {
    c.first = id(k[0]), c.facing_first = k[0].facing;
    if (k.size() == 2) c.second = id(k[1]), c.facing_second = k[1].facing;
  } else {
    c.pinned = true;
  }
  return c;
}

}  // namespace isohex::internal
