// Cutting a hex mesh along implicit surfaces by sheet insertion (see cut.hpp).
#include "isohex/sheets/cut.hpp"

#include "isohex/contour/region.hpp"
#include "isohex/error.hpp"
#include "isohex/mesh/topology.hpp"
#include "isohex/optimize/slide.hpp"
#include "isohex/sheets/internal/cut_steps.hpp"
#include "isohex/sheets/pillow.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
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

using namespace internal;

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

// The mean length of the hexes' edges (each hex's 12; shared edges count once per hex).
double mean_edge_length(const HexMesh& m) {
  double sum = 0;
  for (const Hex& h : m.hexes)
    for (const auto& [a, b] : kHexEdges) sum += (m.points[h[a]] - m.points[h[b]]).norm();
  return m.hexes.empty() ? 0 : sum / (12.0 * static_cast<double>(m.hexes.size()));
}

// What the cuts share: the input's boundary for projections, each vertex's keeps, the cut
// surfaces so far and the mesh as it is cut.
struct Cutting {
  const HexMesh& input;
  const CutOptions& options;
  double scale, tri_tol, reach, edge;
  BoundarySurface tris;  // the input's boundary triangles
  HexMesh& m;
  std::vector<contour::LevelSet> levels;  // the boundary's level sets, then the cuts so far
  int first_cut;                          // levels[first_cut + j] is cut j
  std::vector<Keeps> keeps;

  Cutting(const HexMesh& in, const CutOptions& o, double s, HexMesh& mesh)
      : input(in), options(o), scale(s), tri_tol(1e-12 * s), reach(0.25 * s), edge(mean_edge_length(in)),
        tris(in, o.feature_degrees), m(mesh),
        levels(o.boundary), first_cut(static_cast<int>(o.boundary.size())),
        keeps(boundary_keeps(in, o.boundary, o.feature_degrees)) {
    m = in;
  }

  [[nodiscard]] Placer placer() const {
    return {levels, tris, tri_tol, reach, edge, options.domain ? &*options.domain : nullptr};
  }

  // The sides of the cut (1 = inside), settled, the vertices the cut cannot reach sent to one side;
  // the hexes in `forced` take the given side and keep it.
  std::vector<std::uint8_t> sides(int cut_id, CutStep& step, const std::vector<std::pair<Index, std::uint8_t>>& forced) const {
    const contour::LevelSet& surface = levels[static_cast<std::size_t>(cut_id)];
    const std::vector<std::array<Index, 6>> nb = face_neighbours(m);
    const std::vector<EarlierFace> earlier = faces_on_earlier_cuts(m, nb, keeps, first_cut, surface);
    std::vector<std::uint8_t> locked(m.hexes.size(), 0);
    std::vector<std::uint8_t> side = first_sides(m, nb, surface, options.tie_band);
    for (const auto& [h, to] : forced) side[h] = to, locked[h] = 1;
    settle_sides(m, nb, earlier, locked, side, step.moved_across);
    const Incidence inc = vertex_hexes(m);
    const std::vector<std::array<Index, 2>> edges = build_edges(m);
    const double cos_limit = std::cos(options.feature_degrees * std::numbers::pi / 180.0);
    std::vector<std::uint8_t> next;
    for (int round = 0; round < 20; ++round) {
      const std::size_t unreachable =
          unreachable_to_one_side(m, inc, side, keeps, cut_id, placer(), next, locked);
      if (unreachable + doubled_curve_ends(m, levels, inc, edges, keeps, cos_limit, next, locked) == 0) break;
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
  // vertex onto what it keeps to (those already there stay: |L| within tolerance). Returns where
  // the interface vertices were that cannot be placed (pillowing moved a pinch's hexes across:
  // the caller sends their hexes to one side and cuts again); throws if another vertex cannot be.
  std::vector<Vec3> place_all(int cut_id, const std::vector<Index>& origin, CutStep& step) {
    std::vector<Vec3> moved(m.points.size(), Vec3::Zero()), lost;
    for (Index v = 0; v < m.num_vertices(); ++v) {
      const Keeps& k = keeps[v];
      if (!on_surface(k, cut_id)) continue;
      const Vec3 was = m.points[v];
      if (!placer().place(m.points[v], k)) lost.push_back(was);
      moved[v] = m.points[v] - was;
      ++step.surface_vertices;
      step.curve_vertices += k.size() == 2;
      step.corner_vertices += k.size() >= 3;
    }
    if (!lost.empty()) return lost;
    Vec3 first = Vec3::Zero();
    for (Index v = 0; v < m.num_vertices(); ++v) {
      if (on_surface(keeps[v], cut_id)) continue;
      const Vec3 was = m.points[v];
      if (origin[v] >= 0) m.points[v] += moved[origin[v]];
      if (keeps[v].empty() || placer().place(m.points[v], keeps[v])) continue;
      // Moved with its original, the copy may have no foot on its surface near it (a fold of
      // an isosurface): it goes back there from where pillowing put it instead.
      m.points[v] = was;
      if (!placer().place(m.points[v], keeps[v]) && step.unplaced++ == 0) first = m.points[v];
    }
    if (step.unplaced > 0) throw unreachable_error(step, step.unplaced, first);
    return {};
  }

  static Error unreachable_error(const CutStep& step, std::size_t count, const Vec3& at) {
    return Error(fmt::format("cut: the surface {} cannot be reached from {} vertices of the new sheet: it is tangent to "
                             "the mesh's boundary or to an earlier cut there, or thinner than the cells (e.g. vertex at "
                             "{:.6g} {:.6g} {:.6g}); move or resize it a little",
                             step.surface, count, at.x(), at.y(), at.z()));
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

  CutStep cut_once(const contour::LevelSet& surface) {
    const int cut_id = static_cast<int>(levels.size());
    levels.push_back(surface);
    const HexMesh uncut = m;  // for another try
    const std::vector<Keeps> uncut_keeps = keeps;
    std::vector<std::pair<Index, std::uint8_t>> forced;  // hexes of `uncut` sent to one side
    std::vector<Index> tried;                            // ... about these vertices
    for (int attempt = 0;; ++attempt) {
      CutStep step;
      step.surface = surface.shape() ? to_shape_string(*surface.shape()) : surface.describe();
      std::vector<std::uint8_t> side = sides(cut_id, step, forced);
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
      if (const std::vector<Vec3> lost = place_all(cut_id, origin, step); !lost.empty()) {
        if (attempt == 3) throw unreachable_error(step, lost.size(), lost.front());
        // The interface vertices there were (originals keep their place): their hexes join the
        // side of the vertex's sign, and the cut starts again; the other side if that was tried
        // (pillowing's pinch repair took hexes across again).
        const Incidence inc = vertex_hexes(uncut);
        for (const Vec3& p : lost)
          for (Index v = 0; v < uncut.num_vertices(); ++v)
            if (uncut.points[v] == p) {
              std::uint8_t to = surface.level(p) > 0;
              if (std::count(tried.begin(), tried.end(), v) % 2 == 1) to = !to;
              tried.push_back(v);
              for (Index k = inc.offsets[v]; k < inc.offsets[v + 1]; ++k) forced.emplace_back(inc.ids[k], to);
              break;
            }
        m = uncut;
        keeps = uncut_keeps;
        continue;
      }
      if (options.optimize) {
        step.optimisation = optimise(sheet);
        step.optimized = true;
      }
      return step;
    }
  }
};

}  // namespace

double cut_scale(const HexMesh& input, const CutOptions& options) {
  if (input.hexes.empty()) throw Error("cut: the mesh has no hexes");
  double scale = options.scale;
  if (!(scale > 0)) {
    Vec3 lo = input.points.front(), hi = lo;
    for (const Vec3& p : input.points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    scale = (hi - lo).norm();
  }
  if (!(scale > 0) || !std::isfinite(scale)) throw Error("cut: the mesh has no extent");
  return scale;
}

CutResult cut(const HexMesh& input, const std::vector<Shape>& surfaces, const CutOptions& options) {
  const double scale = cut_scale(input, options);
  std::vector<contour::LevelSet> levels;
  levels.reserve(surfaces.size());
  for (const Shape& s : surfaces) levels.emplace_back(std::make_shared<const Shape>(s), scale);
  return cut(input, levels, options);
}

CutResult cut(const HexMesh& input, const std::vector<contour::LevelSet>& surfaces, const CutOptions& options) {
  if (surfaces.empty()) throw Error("cut: no cut surface given");
  if (surfaces.size() > 100) throw Error("cut: at most 100 cut surfaces");
  if (!(options.offset > 0 && options.offset < 1))
    throw Error(fmt::format("cut: the sheet offset must be in (0, 1), got {}", options.offset));
  const double scale = cut_scale(input, options);

  CutResult res;
  Cutting c(input, options, scale, res.mesh);
  for (const contour::LevelSet& s : surfaces) res.steps.push_back(c.cut_once(s));

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
      const Index in = surfaces[j].level(res.mesh.centroid(q.hex[0])) > 0 ? 0 : 1;
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
        const double d = std::abs(c.levels[s].level(res.mesh.points[v])) / c.levels[s].scale();
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
