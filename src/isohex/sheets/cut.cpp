// Cutting a hex mesh along implicit surfaces by sheet insertion (see cut.hpp).
#include "isohex/sheets/cut.hpp"

#include "isohex/contour/region.hpp"
#include "isohex/error.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/sheets/pillow.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

namespace isohex {

std::string_view cut_keep_name(CutKeep k) {
  switch (k) {
    case CutKeep::both: return "both";
    case CutKeep::inside: return "inside";
    case CutKeep::outside: return "outside";
  }
  return "both";
}

std::optional<CutKeep> cut_keep_from_name(std::string_view name) {
  for (CutKeep k : {CutKeep::both, CutKeep::inside, CutKeep::outside})
    if (name == cut_keep_name(k)) return k;
  return std::nullopt;
}

namespace {

// One thing a vertex keeps to: cut surface `surface`, or (surface < 0) the input's boundary
// triangles that face `facing` (one face of it: a feature edge keeps to two, a corner to three).
struct Keep {
  int surface = -1;
  Vec3 facing = Vec3::Zero();
};
using Keeps = std::vector<Keep>;

// Per boundary vertex of `mesh`: the level sets of `surfaces` it is on; where it is on none,
// the directions of its boundary quads more than `feature_degrees` apart (the triangles).
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

bool on_surface(const Keeps& k, int surface) {
  return std::any_of(k.begin(), k.end(), [&](const Keep& e) { return e.surface == surface; });
}

bool place_newton(Vec3& x, const Keeps& keeps, const std::vector<contour::LevelSet>& levels, const BoundarySurface& tris,
                  double tri_tol, double reach);

// Alternating projections onto each of `keeps` in turn (slower than Newton steps, but they
// settle where the triangles' planes change under the steps: a bumpy boundary).
bool place_by_turns(Vec3& x, const Keeps& keeps, const std::vector<contour::LevelSet>& levels, const BoundarySurface& tris,
                    double tri_tol, double reach) {
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

// Moves x onto everything in `keeps` at once: Newton steps, each the least step that zeroes
// the linearised levels (a level set's L, or the signed distance to the plane of the nearest
// triangle facing the keep's way), else by turns. False if neither settles within `reach`.
bool place(Vec3& x, const Keeps& keeps, const std::vector<contour::LevelSet>& levels, const BoundarySurface& tris,
           double tri_tol, double reach) {
  if (place_newton(x, keeps, levels, tris, tri_tol, reach)) return true;
  return keeps.size() <= 3 && place_by_turns(x, keeps, levels, tris, tri_tol, reach);
}

bool place_newton(Vec3& x, const Keeps& keeps, const std::vector<contour::LevelSet>& levels, const BoundarySurface& tris,
                  double tri_tol, double reach) {
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

// The sides of a cut (1 = inside) by the sign at each hex's centroid, or for a hex on the
// boundary at the mean of its boundary faces' centres (the staircase then meets the boundary
// where the surface does).
std::vector<std::uint8_t> first_sides(const HexMesh& m, const std::vector<std::array<Index, 6>>& nb, const Shape& shape) {
  std::vector<std::uint8_t> side(m.hexes.size());
  for (Index h = 0; h < m.num_hexes(); ++h) {
    Vec3 at = Vec3::Zero();
    int faces = 0;
    for (int f = 0; f < 6; ++f)
      if (nb[h][f] < 0) {
        for (Index v : face_vertices(m.hexes[h], f)) at += m.points[v];
        ++faces;
      }
    side[h] = evaluate(shape, faces ? Vec3(at / (4.0 * faces)) : m.centroid(h)) < 0;
  }
  return side;
}

// The interior faces on an earlier cut's surface (all four vertices on it), as their two hexes,
// with the side of the face's centre: both hexes must take it, or the face would be on the
// interface too and collapse onto the curve of the two surfaces.
struct EarlierFace {
  Index h, g;
  std::uint8_t side;
};
std::vector<EarlierFace> faces_on_earlier_cuts(const HexMesh& m, const std::vector<std::array<Index, 6>>& nb,
                                               const std::vector<Keeps>& keeps, int first_cut, const Shape& shape) {
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
      out.push_back({h, g, static_cast<std::uint8_t>(evaluate(shape, c / 4.0) < 0)});
    }
  return out;
}

// Round after round until nothing changes: the hexes on faces of earlier cuts take those faces'
// sides, and a hex with four or more faces towards the other side moves across (`moved` counts
// those); hexes flagged in `locked` stay.
void settle_sides(const HexMesh& m, const std::vector<std::array<Index, 6>>& nb, const std::vector<EarlierFace>& earlier,
                  const std::vector<std::uint8_t>& locked, std::vector<std::uint8_t>& side, std::size_t& moved) {
  for (int round = 0; round < 100; ++round) {
    bool changed = false;
    for (const EarlierFace& e : earlier)
      for (Index h : {e.h, e.g})
        if (side[h] != e.side && !locked[h]) side[h] = e.side, changed = true;
    std::vector<Index> flip;
    for (Index h = 0; h < m.num_hexes(); ++h) {
      if (locked[h]) continue;
      int across = 0;
      for (Index g : nb[h]) across += g >= 0 && side[g] != side[h];
      if (across >= 4) flip.push_back(h);
    }
    for (Index h : flip) side[h] = !side[h];
    moved += flip.size();
    if (!changed && flip.empty()) break;
  }
}

// Interface vertices on a surface (the boundary, an earlier cut) that the cut does not cross
// near them: their hexes join one side (that of the vertex's sign, or of those of its hexes
// already locked) and are locked there, so that the interface leaves them and settle_sides() does
// not move them back. Returns how many there were.
std::size_t unreachable_to_one_side(const HexMesh& m, const Incidence& inc, const std::vector<std::uint8_t>& side,
                                    const std::vector<Keeps>& keeps, int cut_id, const std::vector<contour::LevelSet>& levels,
                                    const BoundarySurface& tris, double tri_tol, double reach,
                                    std::vector<std::uint8_t>& next, std::vector<std::uint8_t>& locked) {
  next = side;
  std::size_t bad = 0;
  for (Index v = 0; v < m.num_vertices(); ++v) {
    if (keeps[v].empty()) continue;
    bool in = false, out = false;
    for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) (side[inc.ids[k]] ? in : out) = true;
    if (!(in && out)) continue;
    Keeps trial = keeps[v];
    trial.push_back({cut_id, Vec3::Zero()});
    Vec3 x = m.points[v];
    if (place(x, trial, levels, tris, tri_tol, reach)) continue;
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

// Pillows the hexes whose side is `which`; the sides and keeps follow the new mesh (added and
// removed hexes of the shrink set change side, new hexes take `which`, copies their
// original's keeps; `origin` gets each copy's original).
void pillow_side(HexMesh& m, std::vector<std::uint8_t>& side, std::vector<Keeps>& keeps, std::vector<Index>& origin,
                 std::uint8_t which, double offset) {
  std::vector<std::uint8_t> shrink(side.size());
  for (std::size_t h = 0; h < side.size(); ++h) shrink[h] = side[h] == which;
  PillowOptions po;
  po.offset = offset;
  PillowResult p = pillow(m, shrink, po);
  for (Index h : p.added) side[h] = which;
  for (Index h : p.removed) side[h] = !which;
  side.resize(p.mesh.hexes.size(), which);
  for (Index original : p.copy_of) keeps.push_back(keeps[original]), origin.push_back(original);
  m = std::move(p.mesh);
}

// Drops the hexes whose side is not `keep` and the vertices no hex uses; the per-hex and
// per-vertex records follow.
void drop_side(HexMesh& m, std::vector<std::uint8_t>& side, std::vector<Keeps>& keeps, std::vector<Index>& origin,
               std::vector<std::uint8_t>& sheet, std::uint8_t keep) {
  std::vector<std::uint8_t> kept(side.size());
  for (std::size_t h = 0; h < side.size(); ++h) kept[h] = side[h] == keep;
  std::vector<Index> vid, hid;
  HexMesh out = keep_hexes(m, kept, &vid, &hid);
  std::vector<std::uint8_t> out_side(out.hexes.size()), out_sheet(out.hexes.size());
  for (std::size_t h = 0; h < hid.size(); ++h)
    if (hid[h] >= 0) out_side[static_cast<std::size_t>(hid[h])] = side[h], out_sheet[static_cast<std::size_t>(hid[h])] = sheet[h];
  std::vector<Keeps> out_keeps(out.points.size());
  std::vector<Index> out_origin(out.points.size(), -1);
  for (std::size_t v = 0; v < vid.size(); ++v) {
    if (vid[v] < 0) continue;
    const auto w = static_cast<std::size_t>(vid[v]);
    out_keeps[w] = std::move(keeps[v]);
    if (origin[v] >= 0) out_origin[w] = vid[static_cast<std::size_t>(origin[v])];
  }
  m = std::move(out);
  side = std::move(out_side);
  sheet = std::move(out_sheet);
  keeps = std::move(out_keeps);
  origin = std::move(out_origin);
}

// 1 for the vertices within `rings` hex rings of the hexes flagged in `seed`.
std::vector<std::uint8_t> near_hexes(const HexMesh& m, const Incidence& inc, const std::vector<std::uint8_t>& seed,
                                     int rings) {
  std::vector<std::uint8_t> near(m.points.size(), 0);
  for (Index h = 0; h < m.num_hexes(); ++h)
    if (seed[h])
      for (Index v : m.hexes[h]) near[v] = 1;
  for (int r = 0; r < rings; ++r) {
    std::vector<std::uint8_t> next = near;
    for (Index v = 0; v < m.num_vertices(); ++v) {
      if (!near[v]) continue;
      for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k)
        for (Index w : m.hexes[inc.ids[k]]) next[w] = 1;
    }
    near = std::move(next);
  }
  return near;
}

// The optimisers' constraint for a vertex: one or two things to keep to (two faces of the
// input's triangles: a feature edge); three or more pin it.
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

// What the cuts share: the input's boundary for projections, each vertex's keeps, the cut
// surfaces so far and the mesh as it is cut.
struct Cutting {
  const HexMesh& input;
  const CutOptions& options;
  double scale, tri_tol, reach;
  BoundarySurface tris;  // the input's boundary triangles
  HexMesh& m;
  std::vector<contour::LevelSet> levels;  // the boundary's level sets, then the cuts so far
  int first_cut;                          // levels[first_cut + j] is cut j
  std::vector<Keeps> keeps;

  Cutting(const HexMesh& in, const CutOptions& o, double s, HexMesh& mesh)
      : input(in), options(o), scale(s), tri_tol(1e-12 * s), reach(0.25 * s), tris(in, o.feature_degrees), m(mesh),
        levels(o.boundary), first_cut(static_cast<int>(o.boundary.size())),
        keeps(boundary_keeps(in, o.boundary, o.feature_degrees)) {
    m = in;
  }

  // The sides of the cut (1 = inside), settled, the vertices the cut cannot reach sent to one side.
  std::vector<std::uint8_t> sides(int cut_id, const Shape& shape, CutStep& step) const {
    const std::vector<std::array<Index, 6>> nb = face_neighbours(m);
    const std::vector<EarlierFace> earlier = faces_on_earlier_cuts(m, nb, keeps, first_cut, shape);
    std::vector<std::uint8_t> locked(m.hexes.size(), 0);
    std::vector<std::uint8_t> side = first_sides(m, nb, shape);
    settle_sides(m, nb, earlier, locked, side, step.moved_across);
    const Incidence inc = vertex_hexes(m);
    std::vector<std::uint8_t> next;
    for (int round = 0;
         round < 20 && unreachable_to_one_side(m, inc, side, keeps, cut_id, levels, tris, tri_tol, reach, next, locked) > 0;
         ++round) {
      for (std::size_t h = 0; h < side.size(); ++h) step.moved_across += next[h] != side[h];
      side = std::move(next);
      settle_sides(m, nb, earlier, locked, side, step.moved_across);
    }
    step.inside_hexes = static_cast<std::size_t>(std::count(side.begin(), side.end(), 1));
    step.outside_hexes = side.size() - step.inside_hexes;
    if ((step.inside_hexes == 0 || step.outside_hexes == 0) && options.skip_missing) return {};
    if (step.inside_hexes == 0 || step.outside_hexes == 0)
      throw Error(fmt::format("cut: the surface {} misses the mesh: every hex is {} it", step.surface,
                              step.inside_hexes == 0 ? "outside" : "inside"));
    return side;
  }

  // The vertices of the faces between the two sides keep to the cut.
  void mark_interface(int cut_id, const std::vector<std::uint8_t>& side) {
    const std::vector<std::array<Index, 6>> nb = face_neighbours(m);
    std::vector<std::uint8_t> mark(m.points.size(), 0);
    for (Index h = 0; h < m.num_hexes(); ++h)
      for (int f = 0; f < 6; ++f)
        if (const Index g = nb[h][f]; g >= 0 && side[g] != side[h])
          for (Index v : face_vertices(m.hexes[h], f)) mark[v] = 1;
    for (std::size_t v = 0; v < mark.size(); ++v)
      if (mark[v]) keeps[v].push_back({cut_id, Vec3::Zero()});
  }

  // Both sides kept: inside, each block b becomes a new block (in the order of b), so that the
  // pieces of earlier cuts stay apart.
  void split_blocks(const std::vector<std::uint8_t>& side) {
    if (!m.has_blocks()) m.blocks.assign(m.hexes.size(), 0);
    std::vector<Index> inside;
    for (Index h = 0; h < m.num_hexes(); ++h)
      if (side[h]) inside.push_back(m.blocks[h]);
    std::sort(inside.begin(), inside.end());
    inside.erase(std::unique(inside.begin(), inside.end()), inside.end());
    const Index top = *std::max_element(m.blocks.begin(), m.blocks.end());
    for (Index h = 0; h < m.num_hexes(); ++h)
      if (side[h])
        m.blocks[h] = top + 1 + static_cast<Index>(std::lower_bound(inside.begin(), inside.end(), m.blocks[h]) - inside.begin());
  }

  // The interface vertices onto the cut (its curves, its corners); the copies the sheets made
  // of them move with them, so that each sheet keeps its thickness and side; then every other
  // vertex onto what it keeps to (those already there stay: |L| within tolerance).
  void place_all(int cut_id, const std::vector<Index>& origin, CutStep& step) {
    std::vector<Vec3> moved(m.points.size(), Vec3::Zero());
    Vec3 first = Vec3::Zero();
    for (Index v = 0; v < m.num_vertices(); ++v) {
      const Keeps& k = keeps[v];
      if (!on_surface(k, cut_id)) continue;
      const Vec3 was = m.points[v];
      if (!place(m.points[v], k, levels, tris, tri_tol, reach) && step.unplaced++ == 0) first = m.points[v];
      moved[v] = m.points[v] - was;
      ++step.surface_vertices;
      step.curve_vertices += k.size() == 2;
      step.corner_vertices += k.size() >= 3;
    }
    for (Index v = 0; v < m.num_vertices(); ++v) {
      if (on_surface(keeps[v], cut_id)) continue;
      const Vec3 was = m.points[v];
      if (origin[v] >= 0) m.points[v] += moved[origin[v]];
      if (keeps[v].empty() || place(m.points[v], keeps[v], levels, tris, tri_tol, reach)) continue;
      // Moved with its original, the copy may have no foot on its surface near it (a fold of
      // an isosurface): it goes back there from where pillowing put it instead.
      m.points[v] = was;
      if (!place(m.points[v], keeps[v], levels, tris, tri_tol, reach) && step.unplaced++ == 0) first = m.points[v];
    }
    if (step.unplaced > 0)
      throw Error(fmt::format("cut: the surface {} cannot be reached from {} vertices of the new sheet: it is tangent to "
                              "the mesh's boundary or to an earlier cut there (e.g. vertex at {:.6g} {:.6g} {:.6g}); "
                              "move or resize it a little",
                              step.surface, step.unplaced, first.x(), first.y(), first.z()));
  }

  // Untangle, shape and worst pass of the vertices within `rings` of the new sheets, each
  // kept on what it lies on.
  OptimizeResult optimise(const std::vector<std::uint8_t>& sheet) {
    std::vector<BoundarySurface::Constraint> cons(m.points.size());
    for (std::size_t v = 0; v < cons.size(); ++v) cons[v] = constraint_of(keeps[v]);
    const BoundarySurface surface(m, input, levels, cons);
    const Incidence inc = vertex_hexes(m);
    const std::vector<std::uint8_t> near = near_hexes(m, inc, sheet, options.rings);
    std::vector<std::uint8_t> fixed = surface.fixed_mask();
    for (std::size_t v = 0; v < fixed.size(); ++v) fixed[v] = fixed[v] || !near[v];
    OptimizeOptions o = options.optimize_options;
    o.untangle_options.surface = o.shape_options.surface = o.worst_options.surface = &surface;
    o.untangle_options.incidence = o.shape_options.incidence = o.worst_options.incidence = &inc;
    o.untangle_options.progress = o.shape_options.progress = o.worst_options.progress = options.progress;
    return optimize_mesh(m, fixed, o);
  }

  CutStep cut_once(const Shape& shape) {
    CutStep step;
    step.surface = to_shape_string(shape);
    const int cut_id = static_cast<int>(levels.size());
    levels.emplace_back(std::make_shared<const Shape>(shape), scale);
    std::vector<std::uint8_t> side = sides(cut_id, shape, step);
    if (side.empty()) {
      step.missed = true;
      return step;
    }
    const Index before = m.num_hexes();
    std::vector<Index> origin(m.points.size(), -1);  // per vertex: the one it copies (this cut's sheets)
    if (options.keep != CutKeep::outside) pillow_side(m, side, keeps, origin, 1, options.offset);
    if (options.keep != CutKeep::inside) pillow_side(m, side, keeps, origin, 0, options.offset);
    step.sheet_hexes = static_cast<std::size_t>(m.num_hexes() - before);
    std::vector<std::uint8_t> sheet(m.hexes.size(), 0);
    std::fill(sheet.begin() + before, sheet.end(), 1);
    mark_interface(cut_id, side);
    if (options.keep == CutKeep::both) {
      split_blocks(side);
    } else {
      const std::uint8_t kept = options.keep == CutKeep::inside ? 1 : 0;
      step.dropped_hexes = static_cast<std::size_t>(std::count(side.begin(), side.end(), !kept));
      drop_side(m, side, keeps, origin, sheet, kept);
    }
    place_all(cut_id, origin, step);
    if (options.optimize) {
      step.optimisation = optimise(sheet);
      step.optimized = true;
    }
    return step;
  }
};

}  // namespace

CutResult cut(const HexMesh& input, const std::vector<Shape>& surfaces, const CutOptions& options) {
  if (surfaces.empty()) throw Error("cut: no cut surface given");
  if (surfaces.size() > 100) throw Error("cut: at most 100 cut surfaces");
  if (!(options.offset > 0 && options.offset < 1))
    throw Error(fmt::format("cut: the sheet offset must be in (0, 1), got {}", options.offset));
  if (input.hexes.empty()) throw Error("cut: the mesh has no hexes");
  double scale = options.scale;
  if (!(scale > 0)) {
    Vec3 lo = input.points.front(), hi = lo;
    for (const Vec3& p : input.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    scale = (hi - lo).norm();
  }
  if (!(scale > 0) || !std::isfinite(scale)) throw Error("cut: the mesh has no extent");

  CutResult res;
  Cutting c(input, options, scale, res.mesh);
  for (const Shape& s : surfaces) res.steps.push_back(c.cut_once(s));

  // Per cut: its quads (all four vertices on it) and how far its vertices are from it.
  res.surface_quads.resize(surfaces.size());
  res.max_distance.assign(surfaces.size(), 0.0);
  // ... and as face sets for the solvers: "cutJ" (the faces on a surface that is boundary) or
  // "cutJ_inside" / "cutJ_outside" (the two sides of an interface), J from 1.
  std::vector<std::array<FaceSet, 3>> sets(surfaces.size());
  for (const QuadFace& q : build_quads(res.mesh))
    for (std::size_t j = 0; j < surfaces.size(); ++j) {
      if (!std::all_of(q.vertices.begin(), q.vertices.end(),
                       [&](Index v) { return on_surface(c.keeps[v], c.first_cut + static_cast<int>(j)); }))
        continue;
      res.surface_quads[j].push_back(q.vertices);
      if (q.is_boundary()) {
        sets[j][0].faces.push_back({q.hex[0], q.local[0]});
        continue;
      }
      const Index in = evaluate(surfaces[j], res.mesh.centroid(q.hex[0])) < 0 ? 0 : 1;
      sets[j][1].faces.push_back({q.hex[in], q.local[in]});
      sets[j][2].faces.push_back({q.hex[1 - in], q.local[1 - in]});
    }
  for (std::size_t j = 0; j < surfaces.size(); ++j)
    for (int k = 0; k < 3; ++k) {
      FaceSet& fs = sets[j][static_cast<std::size_t>(k)];
      if (fs.faces.empty()) continue;
      std::sort(fs.faces.begin(), fs.faces.end());
      fs.name = fmt::format("cut{}{}", j + 1, k == 0 ? "" : k == 1 ? "_inside" : "_outside");
      res.mesh.face_sets.push_back(std::move(fs));
    }
  for (Index v = 0; v < res.mesh.num_vertices(); ++v)
    for (const Keep& k : c.keeps[v])
      if (k.surface >= c.first_cut) {
        const auto s = static_cast<std::size_t>(k.surface);
        const double d = std::abs(c.levels[s].level(res.mesh.points[v])) / scale;
        double& worst = res.max_distance[s - static_cast<std::size_t>(c.first_cut)];
        worst = std::max(worst, d);
      }
  // What the optimisers after the cut need to keep every vertex where it lies.
  res.surfaces = c.levels;
  res.constraints.resize(res.mesh.points.size());
  for (std::size_t v = 0; v < res.constraints.size(); ++v) res.constraints[v] = constraint_of(c.keeps[v]);
  return res;
}

}  // namespace isohex
