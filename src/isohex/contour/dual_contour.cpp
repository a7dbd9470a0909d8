#include "isohex/contour/dual_contour.hpp"

#include "isohex/contour/cell_cases.hpp"
#include "isohex/contour/qef.hpp"
#include "isohex/contour/sampled_grid.hpp"
#include "isohex/error.hpp"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <utility>

namespace isohex::contour {

namespace {

// Fraction of the cell size kept between a dual vertex (before projection) and its cell's faces.
constexpr double kClampMargin = 0.05;
// Dual vertices of neighbouring cells closer than this (in cells) are placed again, away from
// their cells' faces.
constexpr double kNearVertices = 0.01;


using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

constexpr int kMaxSurfaces = 4;

// Moves p onto surface s keeping the coordinates in `fixed` (bit per axis): Newton steps along
// the gradient with the fixed components removed, then the root once the zero is bracketed.
bool project_within_faces(const LevelSet& s, Vec3& p, unsigned fixed, double max_distance) {
  const Vec3 start = p;
  for (int it = 0; it < 40; ++it) {
    Vec3 g;
    const double l = s.level(p, g);
    if (std::abs(l) <= s.tolerance()) return true;
    for (int a = 0; a < 3; ++a)
      if (fixed & (1u << a)) g[a] = 0;
    const double g2 = g.squaredNorm();
    const double room = max_distance - (p - start).norm();
    if (!(g2 > 0) || room <= 0) return false;
    Vec3 step = -l * g / g2;
    if (step.norm() > room) step *= room / step.norm();
    const Vec3 q = p + step;
    const double lq = s.level(q);
    if ((lq > 0) != (l > 0)) {
      p = l > 0 ? s.root(p, q) : s.root(q, p);
      return std::abs(s.level(p)) <= s.tolerance();
    }
    p = q;
  }
  return false;
}

// Distance from p (in or near the cell [lo, lo + h]^3) to the nearest face of the cell.
double face_clearance(const Vec3& lo, double h, const Vec3& p) {
  double d = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) d = std::min({d, std::abs(p[a] - lo[a]), std::abs(lo[a] + h - p[a])});
  return d;
}

struct Placement {
  Vec3 point;
  std::int8_t place;
  bool fallback;
};

// The dual vertex of the inside component `comp` (corner bit set) of cell (i, j, k).
Placement place_vertex(const Region& region, const SampledGrid& g, std::size_t i, std::size_t j, std::size_t k,
                       std::uint8_t mask, std::uint8_t comp, bool avoid_faces = false) {
  const double h = g.grid.h;
  const Vec3 lo = g.position(i, j, k);
  const Vec3 centre = lo + Vec3::Constant(0.5 * h);
  if (mask == 0xff) return {centre, kInteriorVertex, false};

  Qef qef;
  struct Crossing {
    Vec3 point;
    int surface;
  };
  Crossing crossings[12];
  int num_crossings = 0;
  int per_surface[kMaxSurfaces] = {};
  unsigned box_axes = 0;
  Vec3 box_point = Vec3::Zero();
  Vec3 loose_sum = Vec3::Zero();  // edge midpoints without a true sign change (filled points)
  int loose = 0;
  const int num_surfaces = static_cast<int>(region.surfaces.size());

  for (int c = 0; c < 8; ++c) {
    if (!(comp & (1u << c))) continue;
    for (int a = 0; a < 3; ++a) {
      const int d = c ^ (1 << a);
      if (mask & (1u << d)) continue;  // inside neighbours are in the same component
      const std::size_t ci = i + (c & 1), cj = j + (c >> 1 & 1), ck = k + (c >> 2 & 1);
      const std::size_t di = i + (d & 1), dj = j + (d >> 1 & 1), dk = k + (d >> 2 & 1);
      const Vec3 p = g.position(ci, cj, ck), q = g.position(di, dj, dk);
      if (g.is_padding(di, dj, dk)) {
        // The segment leaves the domain box through the face across axis a.
        const bool upper = (d >> a & 1) != 0;
        Vec3 x = p;
        x[a] = upper ? g.domain.hi[a] : g.domain.lo[a];
        box_point[a] = x[a];
        box_axes |= 1u << a;
        qef.add(x, Vec3::Unit(a));
        continue;
      }
      // The first zero met going from p to q among the surfaces that change sign there.
      int best = -1;
      double best_t = 2;
      Vec3 best_x;
      for (int s = 0; s < num_surfaces; ++s) {
        const LevelSet& ls = region.surfaces[static_cast<std::size_t>(s)];
        if (!(ls.level(p) > 0) || ls.level(q) > 0) continue;
        const Vec3 x = ls.root(p, q);
        const double t = (x - p).norm();
        if (t < best_t * h) {
          best_t = t / h;
          best = s;
          best_x = x;
        }
      }
      if (best < 0) {
        loose_sum += 0.5 * (p + q);
        ++loose;
        continue;
      }
      Vec3 grad;
      region.surfaces[static_cast<std::size_t>(best)].level(best_x, grad);
      qef.add(best_x, grad);
      crossings[num_crossings++] = {best_x, best};
      ++per_surface[std::min(best, kMaxSurfaces - 1)];
    }
  }

  if (num_crossings == 0 && loose > 0) {
    // Every outside edge starts at a point the repair filled (L ≤ 0 there). The surface still
    // passes between those points and the component's truly inside corners: use the zeros
    // on the component's own edges instead.
    for (int c = 0; c < 8; ++c)
      for (int a = 0; a < 3; ++a) {
        const int d = c ^ (1 << a);
        if (d < c || !(comp & (1u << c)) || !(comp & (1u << d))) continue;
        const Vec3 p = g.position(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1));
        const Vec3 q = g.position(i + (d & 1), j + (d >> 1 & 1), k + (d >> 2 & 1));
        for (int s = 0; s < num_surfaces && num_crossings < 12; ++s) {
          const LevelSet& ls = region.surfaces[static_cast<std::size_t>(s)];
          const double lp = ls.level(p), lq = ls.level(q);
          if ((lp > 0) == (lq > 0)) continue;
          const Vec3 x = lp > 0 ? ls.root(p, q) : ls.root(q, p);
          Vec3 grad;
          ls.level(x, grad);
          qef.add(x, grad);
          crossings[num_crossings++] = {x, s};
          ++per_surface[std::min(s, kMaxSurfaces - 1)];
        }
      }
  }

  int surface = -1;
  for (int s = 0; s < std::min(num_surfaces, kMaxSurfaces); ++s)
    if (per_surface[s] > 0 && (surface < 0 || per_surface[s] > per_surface[surface])) surface = s;

  Vec3 x = qef.count() > 0 ? qef.solve() : (loose > 0 ? Vec3(loose_sum / loose) : centre);
  // Clamped a little inside the cell: where the isosurface passes exactly through a grid
  // point, the minimisers of all the cells around it fall on that point, and clamping to the
  // closed cell would give them one position (degenerate hexes, e.g. at a sphere's poles).
  const double margin = kClampMargin * h;
  for (int a = 0; a < 3; ++a) x[a] = std::clamp(x[a], lo[a] + margin, lo[a] + h - margin);

  if (box_axes) {
    for (int a = 0; a < 3; ++a)
      if (box_axes & (1u << a)) x[a] = box_point[a];
    // The projection keeps the box axes but may walk the others past the domain's edge (a crop
    // of cthead at iso 1000 had a vertex of its face x = 35 at z = -0.27, outside for good:
    // sliding refuses to leave the box, not to come back): then the vertex stays in its cell.
    if (surface >= 0) {
      Vec3 y = x;
      if (project_within_faces(region.surfaces[static_cast<std::size_t>(surface)], y, box_axes, h) &&
          region.domain.contains(y))
        x = y;
    }
    return {x, kBoxVertex, false};
  }
  if (surface < 0) {
    // Only flipped points here: project onto the nearest surface within reach. Levels of
    // different surfaces are in different units (values, lengths), so they are compared
    // relative to each surface's scale, and each surface is tried in that order. A flipped
    // point is next to the surface it was flipped across, so allow a longer reach than usual.
    int order[kMaxSurfaces];
    double rel[kMaxSurfaces];
    const int n = std::min(num_surfaces, kMaxSurfaces);
    for (int s = 0; s < n; ++s) {
      const LevelSet& ls = region.surfaces[static_cast<std::size_t>(s)];
      rel[s] = std::abs(ls.level(x)) / ls.scale();
      order[s] = s;
    }
    std::stable_sort(order, order + n, [&](int a, int b) { return rel[a] < rel[b]; });
    for (int k = 0; k < n; ++k) {
      Vec3 y = x;
      if (region.surfaces[static_cast<std::size_t>(order[k])].project(y, 3 * h))
        return {y, static_cast<std::int8_t>(order[k]), false};
    }
    surface = order[0];
    const LevelSet& ls = region.surfaces[static_cast<std::size_t>(surface)];
    // Last resort: the zero between x and the nearest grid point on the other side of the
    // surface within the 4x4x4 points around the cell (one exists: the filled points border
    // truly inside ones).
    const bool x_in = ls.level(x) > 0;
    double best_d = std::numeric_limits<double>::infinity();
    Vec3 other = x;
    for (std::size_t dk = 0; dk < 4; ++dk)
      for (std::size_t dj = 0; dj < 4; ++dj)
        for (std::size_t di = 0; di < 4; ++di) {
          if (i + di < 1 || j + dj < 1 || k + dk < 1 || i + di > g.padded[0] || j + dj > g.padded[1] ||
              k + dk > g.padded[2])
            continue;
          const Vec3 q = g.position(i + di - 1, j + dj - 1, k + dk - 1);
          if ((ls.level(q) > 0) == x_in) continue;
          const double d = (q - x).squaredNorm();
          if (d < best_d) {
            best_d = d;
            other = q;
          }
        }
    if (best_d < std::numeric_limits<double>::infinity()) return {x_in ? ls.root(x, other) : ls.root(other, x),
                                                                  static_cast<std::int8_t>(surface), true};
    return {x, static_cast<std::int8_t>(surface), true};
  }
  Vec3 y = x;
  const LevelSet& ls = region.surfaces[static_cast<std::size_t>(surface)];
  const bool projected = ls.project(y, h);
  // With avoid_faces (the vertex nearly coincides with a neighbour cell's), a projection next
  // to a face of the cell is refused: where the surface touches a grid point, a cell edge or a
  // face (a dimple tangent to it) the projections of the cells around it land on one point.
  if (projected && (!avoid_faces || face_clearance(lo, h, y) >= margin)) return {y, static_cast<std::int8_t>(surface), false};
  // Fall back to a zero on a segment from the clamped minimiser, strictly inside the cell, to a
  // corner on the other side: a point inside the cell. (Not a crossing on the cell's edges: the
  // cells around an edge would all take its crossing, one point for several dual vertices,
  // collapsed quad edges and degenerate hexes that no optimiser can open.) A corner exactly at
  // the isovalue is shared too and is not used. After a failed projection the nearest such
  // corner; after one refused, the zero farthest from the cell's faces (if farther than it).
  const bool x_in = ls.level(x) > 0;
  double best_d = std::numeric_limits<double>::infinity();
  double best_clearance = -1;
  Vec3 other = x, best_z = x;
  for (int c = 0; c < 8; ++c) {
    const Vec3 q = lo + h * Vec3(c & 1, c >> 1 & 1, c >> 2 & 1);
    const double lq = ls.level(q);
    if ((x_in ? lq > 0 : !(lq > 0)) || std::abs(lq) <= ls.tolerance()) continue;
    if (!projected) {
      const double d = (q - x).squaredNorm();
      if (d < best_d) {
        best_d = d;
        other = q;
      }
      continue;
    }
    const Vec3 z = x_in ? ls.root(x, q) : ls.root(q, x);
    const double clearance = face_clearance(lo, h, z);
    if (std::abs(ls.level(z)) <= ls.tolerance() && clearance > best_clearance) {
      best_clearance = clearance;
      best_z = z;
    }
  }
  if (projected)
    return best_clearance > face_clearance(lo, h, y) ? Placement{best_z, static_cast<std::int8_t>(surface), true}
                                                      : Placement{y, static_cast<std::int8_t>(surface), false};
  if (best_d < std::numeric_limits<double>::infinity()) {
    const Vec3 z = x_in ? ls.root(x, other) : ls.root(other, x);
    if (std::abs(ls.level(z)) <= ls.tolerance()) return {z, static_cast<std::int8_t>(surface), true};
  }
  // Else the crossing nearest to the clamped minimiser: it is on the surface.
  int nearest = -1;
  for (int c = 0; c < num_crossings; ++c)
    if (crossings[c].surface == surface &&
        (nearest < 0 || (crossings[c].point - x).squaredNorm() < (crossings[nearest].point - x).squaredNorm()))
      nearest = c;
  return {crossings[nearest].point, static_cast<std::int8_t>(surface), true};
}

// Runs f(k) for every cell slab k in parallel.
template <typename F>
void for_slabs(std::size_t n, F&& f) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k) f(k);
  });
}

// Exclusive prefix sum of per-slab counts; throws if the total overflows Index.
std::vector<std::size_t> prefix(const std::vector<std::size_t>& counts, const char* what) {
  std::vector<std::size_t> first(counts.size() + 1, 0);
  for (std::size_t k = 0; k < counts.size(); ++k) first[k + 1] = first[k] + counts[k];
  if (first.back() > static_cast<std::size_t>(std::numeric_limits<Index>::max()))
    throw Error(fmt::format("the mesh would have {} {} (over 2^31); use a larger cell size", first.back(), what));
  return first;
}

}  // namespace

DualGrid make_grid(const Aabb& domain, double h) {
  if (!(h > 0) || !std::isfinite(h)) throw Error(fmt::format("cell size must be positive and finite (got {})", h));
  DualGrid g;
  g.h = h;
  for (int a = 0; a < 3; ++a) {
    const double extent = domain.hi[a] - domain.lo[a];
    // The small slack keeps the last point when the extent is a multiple of h up to rounding.
    const double n = std::floor(extent / h * (1 + 1e-12) + 1e-9) + 1;
    if (n > 1e9) throw Error(fmt::format("cell size {} is far too small for a box of extent {}", h, extent));
    g.points[a] = static_cast<Index>(n);
    g.origin[a] = domain.lo[a] + 0.5 * std::max(0.0, extent - (n - 1) * h);
  }
  return g;
}

ExtractResult extract_hex_mesh(const Region& region, const ExtractOptions& options) {
  if (region.surfaces.empty() || region.surfaces.size() > kMaxSurfaces) throw Error("a region needs 1 to 4 surfaces");
  const Vec3 extent = region.domain.hi - region.domain.lo;
  double h = options.cell_size;
  if (h <= 0) {
    if (options.resolution < 1) throw Error("resolution must be at least 1 cell");
    h = extent.maxCoeff() / options.resolution;
  }
  ExtractResult out;
  ExtractReport& rep = out.report;
  auto stage = [&](std::string_view name) {
    if (options.on_stage) options.on_stage(name);
    return Clock::now();
  };

  auto t = stage("sampling");
  rep.grid = make_grid(region.domain, h);
  SampledGrid g = sample_region(region, rep.grid);
  rep.time_sample = seconds_since(t);

  t = stage("manifold repair");
  // Filaments thinner than the option are carved first; the repair then mends what that leaves.
  RepairCounts repaired;
  carve_thin_features(g, options.thin_features, repaired);
  {
    RepairCounts rest = repair_manifold(g);
    rest.edits.insert(rest.edits.begin(), repaired.edits.begin(), repaired.edits.end());
    rest.carved += repaired.carved;
    rest.thin = repaired.thin;
    repaired = std::move(rest);
  }
  rep.thin_points = repaired.thin;
  rep.filled_points = repaired.filled;
  rep.carved_points = repaired.carved;
  rep.simple_points = repaired.simple;
  rep.relocated_points = repaired.relocated;
  rep.forced_points = repaired.forced;
  rep.degenerate_components = repaired.degenerate_components;
  rep.degenerate_points = repaired.degenerate;
  rep.zero_level_points = repaired.zero_level;
  rep.pinch_points = repaired.pinch;
  {
    // Each flip's new state, walking back from the final one (a point can flip more than once).
    std::vector<std::uint8_t> state(repaired.edits.size());
    std::unordered_map<std::size_t, std::uint8_t> now;  // state before the later flip of a point
    for (std::size_t e = repaired.edits.size(); e-- > 0;) {
      const std::size_t p = repaired.edits[e].point;
      auto it = now.find(p);
      state[e] = it == now.end() ? g.inside[p] : it->second;
      now[p] = static_cast<std::uint8_t>(!state[e]);
    }
    for (std::size_t e = 0; e < repaired.edits.size(); ++e) {
      const std::size_t p = repaired.edits[e].point;
      const std::size_t i = p % g.padded[0], j = p / g.padded[0] % g.padded[1], k = p / (g.padded[0] * g.padded[1]);
      // Padded index (I, J, K) is grid point (I - 1, J - 1, K - 1).
      rep.edits.push_back({{static_cast<Index>(i) - 1, static_cast<Index>(j) - 1, static_cast<Index>(k) - 1},
                           state[e] != 0, repaired.edits[e].kind});
    }
  }
  rep.repair_rounds = repaired.rounds;
  rep.time_repair = seconds_since(t);

  if (options.min_component > 1) {
    t = stage("components");
    const ComponentCounts cc = remove_small_components(g, static_cast<std::size_t>(options.min_component));
    rep.dropped_components = cc.removed;
    rep.dropped_hexes = cc.removed_points;
    rep.components = cc.kept;
    rep.time_components = seconds_since(t);
  }

  t = stage("dual vertices");
  const std::size_t nx = g.num_cells(0), ny = g.num_cells(1), nz = g.num_cells(2);
  std::vector<std::uint8_t> masks(nx * ny * nz);
  std::vector<std::size_t> slab_vertices(nz, 0), slab_split(nz, 0);
  for_slabs(nz, [&](std::size_t k) {
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        const std::uint8_t m = g.cell_mask(i, j, k);
        masks[i + nx * (j + ny * k)] = m;
        const int n = cell_case(m).num_components;
        slab_vertices[k] += static_cast<std::size_t>(n);
        slab_split[k] += n > 1;
      }
  });
  const std::vector<std::size_t> first_vertex = prefix(slab_vertices, "vertices");
  for (std::size_t s : slab_split) rep.split_cells += s;
  HexMesh& mesh = out.mesh;
  mesh.points.resize(first_vertex.back());
  out.vertex_place.resize(first_vertex.back());
  // Vertex id of each cell's first component; cells without inside corners keep -1.
  std::vector<Index> cell_vertex(masks.size(), -1);
  std::vector<std::uint8_t> fallback(first_vertex.back(), 0);
  const auto component_bits = [](const CellCase& cc, int comp) {
    std::uint8_t bits = 0;
    for (int c = 0; c < 8; ++c)
      if (cc.component[c] == comp) bits |= static_cast<std::uint8_t>(1u << c);
    return bits;
  };
  const auto place = [&](std::size_t i, std::size_t j, std::size_t k, int comp, std::size_t v, bool avoid_faces) {
    const std::uint8_t m = masks[i + nx * (j + ny * k)];
    const Placement pl = place_vertex(region, g, i, j, k, m, component_bits(cell_case(m), comp), avoid_faces);
    mesh.points[v] = pl.point;
    out.vertex_place[v] = pl.place;
    fallback[v] = pl.fallback;
  };
  for_slabs(nz, [&](std::size_t k) {
    std::size_t v = first_vertex[k];
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        const std::size_t cell = i + nx * (j + ny * k);
        if (masks[cell] == 0) continue;
        cell_vertex[cell] = static_cast<Index>(v);
        for (int comp = 0; comp < cell_case(masks[cell]).num_components; ++comp, ++v) place(i, j, k, comp, v, false);
      }
  });
  // Surface vertices of neighbouring cells (or of one cell's components) that nearly coincide
  // are placed again, away from their cells' faces: one point for two dual vertices makes a
  // collapsed edge that no optimiser opens (the MR head at 40, h 4: a dimple tangent to a cell
  // edge). Found first, then moved, so the result does not depend on the order.
  std::vector<std::uint8_t> near(first_vertex.back(), 0);
  std::vector<std::vector<std::pair<std::size_t, int>>> flagged(nz);  // per slab: (cell, component)
  const double near2 = kNearVertices * h * kNearVertices * h;
  for_slabs(nz, [&](std::size_t k) {
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        const std::size_t cell = i + nx * (j + ny * k);
        if (masks[cell] == 0 || masks[cell] == 0xff) continue;
        const auto n = static_cast<std::size_t>(cell_case(masks[cell]).num_components);
        for (std::size_t v = static_cast<std::size_t>(cell_vertex[cell]); v < static_cast<std::size_t>(cell_vertex[cell]) + n; ++v) {
          if (out.vertex_place[v] < 0) continue;
          for (std::size_t c = 0; c < 27 && !near[v]; ++c) {
            const std::size_t ni = i + c % 3, nj = j + c / 3 % 3, nk = k + c / 9;  // offsets -1..1, shifted by 1
            if (ni < 1 || nj < 1 || nk < 1 || ni > nx || nj > ny || nk > nz) continue;
            const std::size_t other = ni - 1 + nx * (nj - 1 + ny * (nk - 1));
            if (masks[other] == 0) continue;
            const auto u0 = static_cast<std::size_t>(cell_vertex[other]);
            for (std::size_t u = u0; u < u0 + static_cast<std::size_t>(cell_case(masks[other]).num_components); ++u)
              if (u != v && (mesh.points[u] - mesh.points[v]).squaredNorm() < near2) near[v] = 1;
          }
          if (near[v]) flagged[k].emplace_back(cell, static_cast<int>(v - static_cast<std::size_t>(cell_vertex[cell])));
        }
      }
  });
  for_slabs(nz, [&](std::size_t k) {
    for (const auto& [cell, comp] : flagged[k])
      place(cell % nx, cell / nx % ny, k, comp, static_cast<std::size_t>(cell_vertex[cell]) + static_cast<std::size_t>(comp), true);
  });
  for (std::size_t v = 0; v < near.size(); ++v) {
    rep.projection_fallbacks += fallback[v];
    rep.separated_vertices += near[v];
  }
  for (std::int8_t p : out.vertex_place) {
    rep.box_vertices += p == kBoxVertex;
    rep.surface_vertices += p >= 0;
  }
  rep.time_vertices = seconds_since(t);

  t = stage("hexes");
  const std::size_t pz = g.padded[2], py = g.padded[1], px = g.padded[0];
  std::vector<std::size_t> slab_hexes(pz, 0);
  for_slabs(pz, [&](std::size_t k) {
    for (std::size_t j = 0; j < py; ++j)
      for (std::size_t i = 0; i < px; ++i) slab_hexes[k] += g.inside[g.index(i, j, k)];
  });
  const std::vector<std::size_t> first_hex = prefix(slab_hexes, "hexes");
  mesh.hexes.resize(first_hex.back());
  // VTK corner order as cell offsets (0 = the cell below the point on that axis).
  static constexpr int kOffsets[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                         {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for_slabs(pz, [&](std::size_t k) {
    std::size_t hx = first_hex[k];
    for (std::size_t j = 0; j < py; ++j)
      for (std::size_t i = 0; i < px; ++i) {
        if (!g.inside[g.index(i, j, k)]) continue;
        Hex& hex = mesh.hexes[hx++];
        for (int v = 0; v < 8; ++v) {
          const std::size_t ci = i - 1 + static_cast<std::size_t>(kOffsets[v][0]);
          const std::size_t cj = j - 1 + static_cast<std::size_t>(kOffsets[v][1]);
          const std::size_t ck = k - 1 + static_cast<std::size_t>(kOffsets[v][2]);
          const std::size_t cell = ci + nx * (cj + ny * ck);
          // The point is corner (1 - offset) of that cell.
          const int corner = (1 - kOffsets[v][0]) | (1 - kOffsets[v][1]) << 1 | (1 - kOffsets[v][2]) << 2;
          hex[v] = cell_vertex[cell] + cell_case(masks[cell]).component[corner];
        }
      }
  });
  rep.inside_points = mesh.hexes.size();
  if (options.min_component <= 1) rep.components = 0;
  rep.time_hexes = seconds_since(t);
  return out;
}

SurfaceDistance surface_distance(const Region& region, const HexMesh& mesh, const std::vector<std::int8_t>& place,
                                 const std::vector<std::uint8_t>* released) {
  SurfaceDistance d;
  const auto n = static_cast<Index>(mesh.points.size());
  std::vector<double> rel(static_cast<std::size_t>(n), -1);
  tbb::parallel_for(Index{0}, n, [&](Index v) {
    const std::int8_t s = place[static_cast<std::size_t>(v)];
    if (s < 0 || static_cast<std::size_t>(s) >= region.surfaces.size()) return;
    const LevelSet& ls = region.surfaces[static_cast<std::size_t>(s)];
    rel[static_cast<std::size_t>(v)] = std::abs(ls.level(mesh.points[static_cast<std::size_t>(v)])) / ls.scale();
  });
  d.max_relative_per_surface.assign(region.surfaces.size(), 0);
  d.checked_per_surface.assign(region.surfaces.size(), 0);
  const double side = (region.domain.hi - region.domain.lo).maxCoeff();
  for (std::size_t v = 0; v < rel.size(); ++v) {
    if (place[v] == kBoxVertex) {
      ++d.box_vertices;
      const Vec3& p = mesh.points[v];
      const double to_box = std::min((p - region.domain.lo).cwiseAbs().minCoeff(), (region.domain.hi - p).cwiseAbs().minCoeff());
      d.box_max_relative = std::max(d.box_max_relative, to_box / side);
    }
    if (rel[v] < 0) continue;
    if (released && v < released->size() && (*released)[v]) {
      ++d.released;
      d.released_max_relative = std::max(d.released_max_relative, rel[v]);
      continue;
    }
    ++d.checked;
    d.max_relative = std::max(d.max_relative, rel[v]);
    d.off_surface += rel[v] > 1e-6;
    d.max_relative_per_surface[static_cast<std::size_t>(place[v])] = std::max(d.max_relative_per_surface[static_cast<std::size_t>(place[v])], rel[v]);
    ++d.checked_per_surface[static_cast<std::size_t>(place[v])];
  }
  return d;
}

}  // namespace isohex::contour
