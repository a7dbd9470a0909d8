// The original boundary surface, its feature edges, and nearest-point projection onto it.
#include "isohex/optimize/slide.hpp"

#include "isohex/error.hpp"
#include "isohex/mesh/topology.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

namespace isohex {

namespace {

// The point of triangle (a, b, c) nearest to p: by the Voronoi regions of its vertices and
// edges (the barycentric coordinates of p's projection decide which region holds it).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

}  // namespace

BoundarySurface::BoundarySurface(const HexMesh& mesh, double feature_degrees) {
  classify(mesh, feature_degrees, true);
}

BoundarySurface::BoundarySurface(const HexMesh& mesh, const IsoField& field, double feature_degrees,
                                 const std::vector<std::uint8_t>* pin) {
  // The field is not owned: the LevelSet gets a non-owning (aliasing) pointer to it.
  surfaces_.emplace_back(std::shared_ptr<const IsoField>(std::shared_ptr<const IsoField>(), &field));
  classify(mesh, feature_degrees, false);
  assign_targets(mesh, std::vector<std::int8_t>(mesh.points.size(), 0), pin);
}

BoundarySurface::BoundarySurface(const HexMesh& mesh, std::vector<contour::LevelSet> surfaces,
                                 const std::vector<std::int8_t>& place, double feature_degrees,
                                 const std::vector<std::uint8_t>* pin)
    : surfaces_(std::move(surfaces)) {
  classify(mesh, feature_degrees, false);
  assign_targets(mesh, place, pin);
}

BoundarySurface::BoundarySurface(const HexMesh& mesh, const HexMesh& triangles_of, std::vector<contour::LevelSet> surfaces,
                                 const std::vector<Constraint>& constraints)
    : surfaces_(std::move(surfaces)) {
  classify(triangles_of, 180.0, true);  // the triangles; the roles are the constraints'
  const std::size_t n = constraints.size();
  role_.assign(n, static_cast<std::uint8_t>(Role::interior));
  target_.assign(n, -1);
  face_.assign(n, -1);
  second_.assign(n, kNone);
  facing_.assign(n, Vec3::Zero());
  facing2_.assign(n, Vec3::Zero());
  const auto valid = [&](std::int8_t k) {
    return k == kNone || (k == kTriangles && !tris_.empty()) || (k >= 0 && static_cast<std::size_t>(k) < surfaces_.size());
  };
  for (std::size_t v = 0; v < n; ++v) {
    Constraint c = constraints[v];
    if (!valid(c.first) || !valid(c.second) || (c.first == kNone && c.second != kNone) ||
        (c.first == c.second && c.first >= 0))
      throw Error(fmt::format("BoundarySurface: vertex {} has an invalid constraint ({}, {})", v, c.first, c.second));
    if (c.first == kTriangles && c.second >= 0) {  // step in the level set's plane
      std::swap(c.first, c.second);
      std::swap(c.facing_first, c.facing_second);
    }
    if (c.first == kTriangles && c.second == kTriangles && (c.facing_first.isZero() || c.facing_second.isZero()))
      throw Error(fmt::format("BoundarySurface: vertex {} on a feature edge needs the facings of both faces", v));
    if (c.pinned) {
      role_[v] = static_cast<std::uint8_t>(Role::pinned);
    } else if (c.first != kNone) {
      role_[v] = static_cast<std::uint8_t>(Role::slides);
      target_[v] = c.first >= 0 ? c.first : -1;
      second_[v] = c.second;
      // After the swap the triangles are the first constraint, or the second beside a level set.
      if (c.first == kTriangles) facing_[v] = c.facing_first, facing2_[v] = c.facing_second;
      else if (c.second == kTriangles) facing_[v] = c.facing_second;
      if (facing_[v].isZero() && (c.first == kTriangles || c.second == kTriangles) && v < mesh.points.size())
        project(mesh.points[v], nullptr, &facing_[v]);
    }
  }
  sliding_ = pinned_ = 0;
  for (std::uint8_t r : role_) {
    sliding_ += r == static_cast<std::uint8_t>(Role::slides);
    pinned_ += r == static_cast<std::uint8_t>(Role::pinned);
  }
}

bool BoundarySurface::project_on_curve(Index v, Vec3& x, double len) const {
  // Gauss–Newton on the two levels: the least step that zeroes both linearisations. The
  // triangles' level is the signed distance to the plane of the nearest triangle facing the
  // vertex's side, found again at every step (two sides on a feature edge of the triangles).
  const double tri_tol = 1e-10 * (hi_ - lo_).norm();
  const auto level = [&](int k, const Vec3& facing, const Vec3& q, Vec3& g, double& tol) {
    if (k == kTriangles) {
      const Vec3 foot = project(q, &facing, &g);
      tol = tri_tol;
      return g.dot(q - foot);
    }
    const contour::LevelSet& s = surfaces_[static_cast<std::size_t>(k)];
    tol = s.tolerance();
    return s.level(q, g);
  };
  const int a = target(v) >= 0 ? target(v) : kTriangles, b = second(v);
  Vec3 q = x;
  for (int it = 0; it < 60; ++it) {
    Vec3 ga, gb;
    double tol_a = 0, tol_b = 0;
    const double ra = level(a, facing_[v], q, ga, tol_a);
    const double rb = level(b, b == kTriangles && a == kTriangles ? facing2_[v] : facing_[v], q, gb, tol_b);
    if (std::abs(ra) <= tol_a && std::abs(rb) <= tol_b) {
      if (!((q - x).norm() <= len)) return false;
      x = q;
      return true;
    }
    const double aa = ga.dot(ga), ab = ga.dot(gb), bb = gb.dot(gb), det = aa * bb - ab * ab;
    if (!(det > 1e-12 * aa * bb)) return false;  // tangent surfaces: no curve to keep to
    const double la = (bb * ra - ab * rb) / det, lb = (aa * rb - ab * ra) / det;
    q -= la * ga + lb * gb;
    if (!q.allFinite() || !((q - x).norm() <= 2 * len)) return false;
  }
  return false;
}

void BoundarySurface::assign_targets(const HexMesh& mesh, const std::vector<std::int8_t>& place,
                                     const std::vector<std::uint8_t>* pin) {
  // A vertex slides only on its own surface, and only when it is on it and on no other: where
  // two surfaces meet (a box's edges) it could slide along neither without cutting the other's
  // corner off the domain. The exception is a rim, a curved surface on one box face: there the
  // vertex slides along their curve of intersection, on both at once.
  target_.assign(role_.size(), -1);
  face_.assign(role_.size(), -1);
  for (std::size_t v = 0; v < role_.size(); ++v) {
    if (role_[v] != static_cast<std::uint8_t>(Role::slides)) continue;
    const int k = v < place.size() ? place[v] : -1;
    bool slides = k >= 0 && static_cast<std::size_t>(k) < surfaces_.size() && !(pin && v < pin->size() && (*pin)[v] != 0) &&
                  surfaces_[static_cast<std::size_t>(k)].on(mesh.points[v]);
    std::vector<int> others;
    for (std::size_t j = 0; slides && j < surfaces_.size(); ++j)
      if (j != static_cast<std::size_t>(k) && surfaces_[j].on(mesh.points[v])) others.push_back(static_cast<int>(j));
    // A rim: a curved surface and one box face. The vertex slides on the curved one and
    // keeps to the plane (whichever of the two its place names).
    int target = k, face = -1;
    if (slides && others.size() == 1) {
      const contour::LevelSet &a = surfaces_[static_cast<std::size_t>(k)], &b = surfaces_[static_cast<std::size_t>(others[0])];
      if (a.box_face() < 0 && b.box_face() >= 0) face = others[0];
      else if (a.box_face() >= 0 && b.box_face() < 0) target = others[0], face = k;
      slides = face >= 0;
    } else if (!others.empty()) {
      slides = false;
    }
    if (slides) {
      target_[v] = static_cast<std::int8_t>(target);
      face_[v] = static_cast<std::int8_t>(face);
    } else {
      role_[v] = static_cast<std::uint8_t>(Role::pinned);
    }
  }
  sliding_ = pinned_ = 0;
  for (std::uint8_t r : role_) {
    sliding_ += r == static_cast<std::uint8_t>(Role::slides);
    pinned_ += r == static_cast<std::uint8_t>(Role::pinned);
  }
}

std::size_t BoundarySurface::num_sliding_on(std::size_t k) const {
  return static_cast<std::size_t>(std::count(target_.begin(), target_.end(), static_cast<std::int8_t>(k)));
}

bool BoundarySurface::tangent_normal(Index v, const Vec3& x, Vec3& n) const {
  if (on_triangles(v)) {
    n = Vec3::Zero();
    // On a feature edge (both constraints the triangles): the first face's normal; the step
    // in its plane is put back on the edge.
    project(x, second(v) == kTriangles ? &facing_[v] : nullptr, &n);
    return true;
  }
  if (target(v) < 0) return false;
  Vec3 g;
  surfaces_[target(v)].level(x, g);
  const double gn = g.norm();
  if (!(gn > 0) || !std::isfinite(gn)) return false;
  n = -g / gn;  // outward: L is positive inside
  return true;
}

bool BoundarySurface::reproject(Index v, Vec3& x, const Vec3& n, double len) const {
  if (second(v) != kNone) return project_on_curve(v, x, len);
  if (on_triangles(v)) {
    x = project(x, &n);
    return true;
  }
  if (target(v) < 0) return false;
  Vec3 p = x;
  const contour::LevelSet& s = surfaces_[target(v)];
  if (!(on_face(v) >= 0 ? s.project_on_face(p, len, surfaces_[on_face(v)]) : s.project(p, len))) return false;
  // An isosurface goes on past the domain's faces (the field is extended there): a foot
  // beyond them is refused (cthead's bone, iso 1200 at h 4, had ended with a vertex 0.17 mm
  // above its top face).
  if (!in_domain(p)) return false;
  x = p;
  return true;
}

bool BoundarySurface::in_domain(const Vec3& x) const {
  return !has_domain_ || domain_.contains(x, 1e-9 * (domain_.hi - domain_.lo).norm());
}

std::size_t BoundarySurface::loosen(const HexMesh& mesh, const std::vector<Index>& vertices, double band) {
  std::size_t n = 0;
  // Exact surfaces stay exact: a vertex on a shape (a cut surface) is not released, nor a corner
  // where constraints pinned it; one on a cut's crease with an isosurface only after
  // set_release_creases(), about the isosurface while it stays on the cut (band_clamp()).
  const auto on_shape = [&](int k) { return exact(k); };
  for (Index v : vertices) {
    if (v < 0 || static_cast<std::size_t>(v) >= role_.size()) continue;
    if (on_shape(target(v))) continue;
    if (on_shape(second(v)) &&
        !(release_creases_ && target(v) >= 0 && surfaces_[static_cast<std::size_t>(target(v))].field()))
      continue;
    if (role_[v] == static_cast<std::uint8_t>(Role::pinned) && !second_.empty()) continue;
    if (role_[v] == static_cast<std::uint8_t>(Role::pinned)) {
      // On the input's own triangles, a feature vertex is released about them; on level sets a
      // rim vertex about the first isosurface it is on (box faces and spheres are exact).
      if (!on_triangles(v)) {
        std::size_t k = 0;
        while (k < surfaces_.size() && !(surfaces_[k].field() && surfaces_[k].on(mesh.points[v]))) ++k;
        if (k == surfaces_.size()) continue;
        target_[v] = static_cast<std::int8_t>(k);
      }
      unpinned_.resize(role_.size(), 0);
      unpinned_[v] = 1;
      --pinned_;
    } else if (role_[v] == static_cast<std::uint8_t>(Role::slides)) {
      --sliding_;
    } else {
      continue;
    }
    role_[v] = static_cast<std::uint8_t>(Role::loose);
    ++n;
  }
  loose_ += n;
  band_ = band;
  if (reach_unit_ == 0) reach_unit_ = band;
  return n;
}

bool BoundarySurface::snap(Index v, Vec3& x, double len) const {
  if (on_triangles(v)) {
    x = project(x);
    return true;
  }
  if (on_face(v) >= 0 || second(v) != kNone) return reproject(v, x, Vec3::Zero(), len);
  Vec3 foot;
  if (!foot_point(v, x, kFootReach * band_, foot) || !in_domain(foot)) return false;
  x = foot;
  return true;
}

bool BoundarySurface::reattach(Index v) {
  if (role(v) != Role::loose || (!unpinned_.empty() && unpinned_[v])) return false;
  role_[v] = static_cast<std::uint8_t>(Role::slides);
  --loose_;
  ++sliding_;
  return true;
}

bool BoundarySurface::foot_point(Index v, const Vec3& x, double max_reach, Vec3& foot) const {
  if (on_triangles(v)) {
    foot = project(x);
    return true;
  }
  if (target(v) < 0) return false;
  // The shortest reach first: the Newton walk of a wider one can wander off to a farther part
  // of a noisy isosurface. Then a sign change within it: on a scan's plateau Newton's steps
  // can fail there and find a foot far away. The reaches start at the first band loosen() was
  // given, whatever the band now: a vertex clamped in the first band then has the same foot in
  // a wider one (with the reaches of each band, cthead h 5 plane y = 100 measured a vertex
  // clamped in 1.5 mm at 6.3 mm in 2.5 and failed its band check; the skin was 2.5 away). So
  // the last reach is the first doubling at or past max_reach, not max_reach itself (h 4 y =
  // 60: a foot found at 16 in a band of 2 was 13 away at 19.2 in 3.33). The same sequence
  // from the same point gives the same foot, so band_clamp() and offset() agree.
  const contour::LevelSet& s = surfaces_[target(v)];
  const double first = reach_unit_ > 0 ? std::min(reach_unit_, max_reach) : max_reach;
  for (double reach = first;; reach *= 2) {
    foot = x;
    if (s.project(foot, reach)) return true;
    if (reach == first && s.field()) {
      foot = x;
      if (s.bracket(foot, first)) return true;
    }
    if (reach >= max_reach) return false;
  }
}

bool BoundarySurface::band_clamp(Index v, Vec3& x, double /*len*/) const {
  // Box, then band, then the box again: the foot point need not be in the box (an isosurface
  // goes on past the domain's faces), so the step to the band's edge may leave it.
  const auto clamp = [&] {
    if (has_domain_) x = x.cwiseMax(domain_.lo).cwiseMin(domain_.hi);
  };
  clamp();
  // The projection follows the gradient, not the straight line to the nearest point, so the
  // foot seen from the clamped point can differ a little: a few rounds settle it, and a step
  // whose foot does not settle is refused.
  // A crease vertex released about its isosurface keeps to its cut (exact): onto it first,
  // and again after each step to the band's edge, until both hold.
  const contour::LevelSet* cut = exact(second(v)) ? &surfaces_[static_cast<std::size_t>(second(v))] : nullptr;
  if (cut && !cut->project(x, kFootReach * band_)) return false;
  Vec3 foot;
  for (int round = 0; round < (cut ? 20 : 5); ++round) {
    // The same reaches as offset(): a wider first reach (a long step) could find another foot
    // than offset() later does from the same point, and the band would not hold as measured.
    if (!foot_point(v, x, kFootReach * band_, foot)) return false;
    const Vec3 d = x - foot;
    const double dn = d.norm();
    if (!(dn > band_ * (1 + 1e-6))) return true;
    x = foot + d * (band_ / dn);
    clamp();
    if (cut && !cut->project(x, kFootReach * band_)) return false;
  }
  return false;
}

bool BoundarySurface::put_back(Index v, Vec3& x, const Vec3& n, double len) const {
  switch (role(v)) {
    case Role::slides: return reproject(v, x, n, len);
    case Role::loose: return band_clamp(v, x, len);
    default: return true;
  }
}

BoundarySurface::Fit BoundarySurface::fit(const HexMesh& mesh) const {
  Fit f;
  for (Index v = 0; v < mesh.num_vertices(); ++v) {
    if (role(v) == Role::slides) f.max_deviation = std::max(f.max_deviation, deviation(v, mesh.points[v]));
    if (role(v) == Role::loose) f.max_offset = std::max(f.max_offset, offset(v, mesh.points[v]));
  }
  return f;
}

double BoundarySurface::offset(Index v, const Vec3& x) const {
  if (on_triangles(v)) return (project(x) - x).norm();
  if (target(v) < 0) return 0;
  Vec3 foot;
  if (foot_point(v, x, kFootReach * band_, foot)) return (foot - x).norm();
  // No foot point within reach (a flat spot of the field): the first-order distance |L| / |∇L|.
  Vec3 g;
  const double l = surfaces_[target(v)].level(x, g);
  return g.norm() > 0 ? std::abs(l) / g.norm() : std::numeric_limits<double>::infinity();
}

double BoundarySurface::deviation(Index v, const Vec3& x) const {
  if (on_triangles(v)) return (project(x) - x).norm();
  if (target(v) < 0) return 0;
  const contour::LevelSet& s = surfaces_[target(v)];
  return std::abs(s.level(x)) / s.scale();
}

void BoundarySurface::classify(const HexMesh& mesh, double feature_degrees, bool keep_triangles) {
  const std::vector<Quad> quads = boundary_quads(mesh);
  role_.assign(mesh.points.size(), static_cast<std::uint8_t>(Role::interior));
  std::vector<Vec3> qn(quads.size());
  std::map<std::pair<Index, Index>, std::vector<std::size_t>> edge_quads;
  double edge_sum = 0;
  for (std::size_t q = 0; q < quads.size(); ++q) {
    const Quad& Q = quads[q];
    const auto P = [&](int i) -> const Vec3& { return mesh.points[Q[i]]; };
    const Vec3 n = (P(2) - P(0)).cross(P(3) - P(1));
    qn[q] = n.norm() > 0 ? Vec3(n.normalized()) : Vec3::Zero();
    for (int i = 0; i < 4; ++i) {
      const Index a = Q[i], b = Q[(i + 1) % 4];
      edge_quads[{std::min(a, b), std::max(a, b)}].push_back(q);
      edge_sum += (P((i + 1) % 4) - P(i)).norm();
      role_[a] = static_cast<std::uint8_t>(Role::slides);
    }
    if (!keep_triangles) continue;
    for (const auto& t : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
      tris_.push_back({P(t[0]), P(t[1]), P(t[2])});
      const Vec3 tn = (P(t[1]) - P(t[0])).cross(P(t[2]) - P(t[0]));
      normals_.push_back(tn.norm() > 0 ? Vec3(tn.normalized()) : qn[q]);
    }
  }
  // Feature edges: a crease sharper than the threshold, or not exactly two boundary quads
  // (a non-manifold or open boundary). Their vertices are pinned: a vertex sliding across a
  // crease would cut the corner off the domain.
  const double cos_limit = std::cos(feature_degrees * std::numbers::pi / 180.0);
  for (const auto& [e, qs] : edge_quads)
    if (qs.size() != 2 || qn[qs[0]].dot(qn[qs[1]]) < cos_limit)
      role_[e.first] = role_[e.second] = static_cast<std::uint8_t>(Role::pinned);
  for (std::uint8_t r : role_) {
    sliding_ += r == static_cast<std::uint8_t>(Role::slides);
    pinned_ += r == static_cast<std::uint8_t>(Role::pinned);
  }
  if (tris_.empty()) return;

  // The grid: cells about one boundary edge long (capped at ~2 M cells).
  lo_ = hi_ = tris_[0][0];
  for (const auto& t : tris_)
    for (const Vec3& p : t) {
      lo_ = lo_.cwiseMin(p);
      hi_ = hi_.cwiseMax(p);
    }
  cell_ = std::max(edge_sum / (4.0 * static_cast<double>(quads.size())), 1e-300);
  const Vec3 ext = hi_ - lo_;
  while ((ext[0] / cell_ + 1) * (ext[1] / cell_ + 1) * (ext[2] / cell_ + 1) > 2e6) cell_ *= 2;
  for (int j = 0; j < 3; ++j) dims_[j] = static_cast<int>(ext[j] / cell_) + 1;
  const auto cell_of = [&](const Vec3& p, int j) {
    return std::clamp(static_cast<int>((p[j] - lo_[j]) / cell_), 0, dims_[j] - 1);
  };
  const std::size_t ncell = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
  start_.assign(ncell + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<std::size_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t t = 0; t < tris_.size(); ++t) {
      Vec3 a = tris_[t][0], b = a;
      for (const Vec3& p : tris_[t]) {
        a = a.cwiseMin(p);
        b = b.cwiseMax(p);
      }
      for (int z = cell_of(a, 2); z <= cell_of(b, 2); ++z)
        for (int y = cell_of(a, 1); y <= cell_of(b, 1); ++y)
          for (int x = cell_of(a, 0); x <= cell_of(b, 0); ++x) {
            const std::size_t c = (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + x;
            if (pass == 0) ++start_[c + 1];
            else items_[fill[c]++] = static_cast<std::uint32_t>(t);
          }
    }
    if (pass == 0) {
      for (std::size_t c = 0; c < ncell; ++c) start_[c + 1] += start_[c];
      items_.resize(start_.back());
    }
  }
}

std::vector<std::uint8_t> BoundarySurface::fixed_mask() const {
  std::vector<std::uint8_t> f(role_.size(), 0);
  for (std::size_t v = 0; v < role_.size(); ++v) f[v] = role_[v] == static_cast<std::uint8_t>(Role::pinned);
  return f;
}

Vec3 BoundarySurface::project(const Vec3& x, const Vec3* facing, Vec3* normal) const {
  Vec3 best = x;
  double best_d2 = std::numeric_limits<double>::infinity();
  std::size_t best_t = tris_.size();
  if (tris_.empty()) return x;
  int c[3];
  for (int j = 0; j < 3; ++j) c[j] = std::clamp(static_cast<int>(std::floor((x[j] - lo_[j]) / cell_)), 0, dims_[j] - 1);
  // Rings of cells around x's cell: every triangle point within k cells of x (less x's distance
  // outside the grid) lies in ring k or inside it, so once the best distance is that small the
  // search is exact.
  const double outside = (x - x.cwiseMax(lo_).cwiseMin(hi_)).norm();
  const int kmax = std::max({dims_[0], dims_[1], dims_[2]});
  for (int k = 0; k <= kmax; ++k) {
    for (int z = std::max(c[2] - k, 0); z <= std::min(c[2] + k, dims_[2] - 1); ++z)
      for (int y = std::max(c[1] - k, 0); y <= std::min(c[1] + k, dims_[1] - 1); ++y)
        for (int xx = std::max(c[0] - k, 0); xx <= std::min(c[0] + k, dims_[0] - 1); ++xx) {
          // Only the shell of ring k: the inside was searched before.
          if (std::max({std::abs(z - c[2]), std::abs(y - c[1]), std::abs(xx - c[0])}) != k) continue;
          const std::size_t cell = (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0] + xx;
          for (std::size_t i = start_[cell]; i < start_[cell + 1]; ++i) {
            const std::size_t t = items_[i];
            if (facing && !(normals_[t].dot(*facing) > 0)) continue;
            const Vec3 p = closest_on_triangle(x, tris_[t][0], tris_[t][1], tris_[t][2]);
            const double d2 = (p - x).squaredNorm();
            if (d2 < best_d2 || (d2 == best_d2 && t < best_t)) {
              best_d2 = d2;
              best = p;
              best_t = t;
            }
          }
        }
    const double reach = k * cell_ - outside;
    if (best_t < tris_.size() && reach > 0 && best_d2 <= reach * reach) break;
  }
  if (normal && best_t < tris_.size()) *normal = normals_[best_t];
  return best;
}

}  // namespace isohex
