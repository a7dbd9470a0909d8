#include "isohex/contour/refine_boundary.hpp"

#include "isohex/mesh/refine.hpp"
#include "isohex/mesh/topology.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace isohex::contour {

namespace {

using Clock = std::chrono::steady_clock;

// The surface all four corners of a quad lie on, or -1 (a box quad, or one spanning two
// surfaces: left alone, the box is flat and a seam has no single surface to follow).
int quad_surface(const std::vector<std::int8_t>& place, const Quad& q) {
  const std::int8_t s = place[static_cast<std::size_t>(q[0])];
  if (s < 0) return -1;
  for (int c = 1; c < 4; ++c)
    if (place[static_cast<std::size_t>(q[c])] != s) return -1;
  return s;
}

struct ChordScan {
  std::vector<std::pair<double, Quad>> coarse;  // (chord, quad) over the limit, deepest first
  std::size_t unreachable = 0;
  double max_chord = 0;   // world units
  double mean_chord = 0;  // area-weighted over the quads on a surface
};

// The boundary quads on a surface that chord it deeper than `limit`, and the chord statistics.
ChordScan scan_chords(const Region& region, const HexMesh& mesh, const std::vector<std::int8_t>& place, double h,
                      double limit) {
  const std::vector<Quad> quads = boundary_quads(mesh);
  std::vector<double> chord(quads.size(), -2);  // -2: not on one surface; -1: unreachable
  tbb::parallel_for(std::size_t{0}, quads.size(), [&](std::size_t i) {
    const int s = quad_surface(place, quads[i]);
    if (s >= 0) chord[i] = quad_chord(region.surfaces[static_cast<std::size_t>(s)], mesh, quads[i], h);
  });
  ChordScan scan;
  double area_sum = 0, weighted = 0;
  for (std::size_t i = 0; i < quads.size(); ++i) {
    // A quad whose points do not reach the surface within a cell (a fold of a noisy scan's
    // surface) is left alone: its new vertices could not be placed on the surface either.
    if (chord[i] == -1) ++scan.unreachable;
    if (chord[i] < 0) continue;
    const Quad& q = quads[i];
    const auto& x = mesh.points;
    const double area = 0.5 * (x[q[2]] - x[q[0]]).cross(x[q[3]] - x[q[1]]).norm();
    area_sum += area;
    weighted += area * chord[i];
    scan.max_chord = std::max(scan.max_chord, chord[i]);
    if (chord[i] > limit) scan.coarse.emplace_back(chord[i], q);
  }
  scan.mean_chord = area_sum > 0 ? weighted / area_sum : 0;
  // Deepest first; ties in the quads' order, which is deterministic.
  std::stable_sort(scan.coarse.begin(), scan.coarse.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  return scan;
}

// Marks the corners of the coarse quads, deepest first, each only if the templates' promotion
// then marks at most `budget` more vertices. Marking a quad's corners alone gives its hex the
// face template (the quad split 3 x 3, the opposite face whole), but where marked corners form
// no template in some hex (a staircase hex with two marked faces, a diagonal pair) promotion
// marks all 8 of its corners, which can spread through the whole boundary layer; the budget
// keeps the refinement where it was asked for.
std::vector<std::uint8_t> mark_within_budget(const HexMesh& mesh, const ChordScan& scan, std::size_t budget,
                                             std::size_t& accepted, std::size_t& promoted) {
  std::vector<std::uint8_t> marked(mesh.points.size(), 0);
  const Incidence around = vertex_hexes(mesh);
  std::vector<Index> seeds;
  for (const auto& [chord, quad] : scan.coarse) {
    seeds.clear();
    for (Index v : quad)
      if (!marked[static_cast<std::size_t>(v)]) marked[static_cast<std::size_t>(v)] = 1, seeds.push_back(v);
    const std::vector<Index> corners = seeds;
    const std::size_t extra = close_marks(mesh, around, marked, std::move(seeds), budget);
    if (extra > budget) {
      for (Index v : corners) marked[static_cast<std::size_t>(v)] = 0;
    } else {
      ++accepted;
      promoted += extra;
    }
  }
  return marked;
}

// Where a new vertex lies: the place its source vertices share if they are all on one
// surface or all on the box; a surface if they mix the box and one surface (a rim quad);
// interior if any source is interior or they span two surfaces.
std::int8_t source_place(const std::vector<std::int8_t>& place, const Index* ids, const Index* end) {
  std::int8_t surface = kInteriorVertex;
  bool box = false;
  for (const Index* p = ids; p != end; ++p) {
    const std::int8_t s = place[static_cast<std::size_t>(*p)];
    if (s == kInteriorVertex) return kInteriorVertex;
    if (s == kBoxVertex) {
      box = true;
    } else if (surface == kInteriorVertex) {
      surface = s;
    } else if (s != surface) {
      return kInteriorVertex;
    }
  }
  if (surface != kInteriorVertex) return surface;
  return box ? std::int8_t{kBoxVertex} : std::int8_t{kInteriorVertex};
}

}  // namespace

double quad_chord(const LevelSet& s, const HexMesh& mesh, const Quad& q, double max_distance) {
  const Vec3& a = mesh.points[static_cast<std::size_t>(q[0])];
  const Vec3& b = mesh.points[static_cast<std::size_t>(q[1])];
  const Vec3& c = mesh.points[static_cast<std::size_t>(q[2])];
  const Vec3& d = mesh.points[static_cast<std::size_t>(q[3])];
  const Vec3 probes[5] = {0.25 * (a + b + c + d), 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + d), 0.5 * (d + a)};
  double deepest = 0;
  for (const Vec3& p : probes) {
    // The distance a projection travels, not |L| / |∇L|: on scans the gradient nearly vanishes
    // in places and the first-order estimate runs to many cells.
    Vec3 x = p;
    if (!s.project(x, max_distance)) return -1;
    deepest = std::max(deepest, (x - p).norm());
  }
  return deepest;
}

BoundaryRefineReport refine_boundary(const Region& region, ExtractResult& extracted, const BoundaryRefineOptions& options) {
  const auto start = Clock::now();
  BoundaryRefineReport report;
  HexMesh& mesh = extracted.mesh;
  std::vector<std::int8_t>& place = extracted.vertex_place;
  report.hexes_before = mesh.hexes.size();
  const double h = extracted.report.grid.h;
  const double limit = options.chord_tolerance * h;

  ChordScan scan = scan_chords(region, mesh, place, h, limit);
  report.coarse_quads = scan.coarse.size();
  report.unreachable_quads = scan.unreachable;
  report.max_chord_before = scan.max_chord / h;
  report.mean_chord_before = scan.mean_chord / h;
  for (int level = 0; level < options.levels && !scan.coarse.empty(); ++level) {
    const auto n_old = static_cast<Index>(mesh.points.size());
    std::size_t accepted = 0, promoted = 0;
    std::vector<std::uint8_t> marked = mark_within_budget(mesh, scan, options.promotion_budget, accepted, promoted);
    report.refined_quads += accepted;
    if (accepted == 0) break;
    for (std::uint8_t m : marked) report.marked_vertices += m;
    RefineResult r = refine(mesh, std::move(marked));
    report.promoted_vertices += promoted;  // refine() adds none: the marks are closed already
    const auto n_new = static_cast<Index>(r.mesh.points.size());

    // Places of the new vertices, then the new boundary vertices onto their surfaces. A new
    // vertex is on the boundary only if it lies on a boundary quad of the refined mesh; the
    // templates put it on the parent's bilinear face, within a chord of the surface.
    std::vector<std::int8_t> new_place(static_cast<std::size_t>(n_new), kInteriorVertex);
    std::copy(place.begin(), place.end(), new_place.begin());
    const std::vector<std::uint8_t> on_boundary = boundary_vertex_mask(r.mesh);
    for (Index v = n_old; v < n_new; ++v) {
      if (!on_boundary[static_cast<std::size_t>(v)]) continue;
      const auto k = static_cast<std::size_t>(v - n_old);
      const Index* ids = r.source_ids.data();
      new_place[static_cast<std::size_t>(v)] = source_place(place, ids + r.source_offsets[k], ids + r.source_offsets[k + 1]);
    }
    std::vector<std::uint8_t> failed(static_cast<std::size_t>(n_new), 0);
    tbb::parallel_for(n_old, n_new, [&](Index v) {
      const std::int8_t s = new_place[static_cast<std::size_t>(v)];
      if (s < 0) return;
      const LevelSet& surface = region.surfaces[static_cast<std::size_t>(s)];
      const Vec3 start = r.mesh.points[static_cast<std::size_t>(v)];
      Vec3 p = start;
      bool placed = surface.project(p, h);
      // Where the face bulges far from the surface (a fold), start halfway to a source vertex
      // on the surface, in source order, so that the result does not depend on threads.
      const auto k = static_cast<std::size_t>(v - n_old);
      for (Index i = r.source_offsets[k]; !placed && i < r.source_offsets[k + 1]; ++i) {
        const Index src = r.source_ids[static_cast<std::size_t>(i)];
        if (place[static_cast<std::size_t>(src)] != s) continue;
        p = 0.5 * (start + r.mesh.points[static_cast<std::size_t>(src)]);
        placed = surface.project(p, h);
      }
      if (placed) r.mesh.points[static_cast<std::size_t>(v)] = p;
      else failed[static_cast<std::size_t>(v)] = 1;
    });
    for (Index v = n_old; v < n_new; ++v) {
      const std::int8_t s = new_place[static_cast<std::size_t>(v)];
      if (s < 0) continue;
      ++report.projected_vertices;
      // Left off its surface but still labelled with it, so that the verification fails it.
      report.projection_failures += failed[static_cast<std::size_t>(v)];
    }
    mesh = std::move(r.mesh);
    place = std::move(new_place);
    ++report.levels;
    scan = scan_chords(region, mesh, place, h, limit);
  }
  report.coarse_quads_after = scan.coarse.size();
  report.max_chord_after = scan.max_chord / h;
  report.mean_chord_after = scan.mean_chord / h;
  report.hexes_after = mesh.hexes.size();
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

}  // namespace isohex::contour
