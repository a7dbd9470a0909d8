// CSG solids meshed by cuts along the smooth pieces of their primitives (see csg_cuts.hpp).
#include "isohex/sheets/csg_cuts.hpp"

#include "isohex/error.hpp"
#include "isohex/mesh/generate.hpp"
#include "isohex/mesh/topology.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace isohex {

namespace {

void collect(const Shape& s, double reach, std::vector<Shape>& out) {
  if (const auto* c = std::get_if<Csg>(&s.node)) {
    for (const Shape& o : c->operands) collect(o, reach, out);
  } else if (const auto* b = std::get_if<Box>(&s.node)) {
    // Six half-spaces, each with the box on its inside (behind the outward normal).
    for (int a = 0; a < 3; ++a) {
      Vec3 n = Vec3::Zero();
      n[a] = -1;
      out.push_back(Shape::plane(b->lo, n));
      n[a] = 1;
      out.push_back(Shape::plane(b->hi, n));
    }
  } else if (const auto* cy = std::get_if<Cylinder>(&s.node)) {
    const Vec3 axis = (cy->b - cy->a).normalized();
    out.push_back(Shape::cylinder(cy->a - reach * axis, cy->b + reach * axis, cy->radius));
    out.push_back(Shape::plane(cy->a, -axis));
    out.push_back(Shape::plane(cy->b, axis));
  } else {
    out.push_back(s);  // sphere, torus, half-space: one smooth surface
  }
}

// A plane that is a face of `box` (its normal along an axis, its point on that face).
bool is_face_of(const Shape& s, const Aabb& box) {
  const auto* h = std::get_if<HalfSpace>(&s.node);
  if (!h) return false;
  for (int a = 0; a < 3; ++a) {
    const Vec3 n = h->normal / h->normal.norm();
    if (std::abs(std::abs(n[a]) - 1) > 1e-12) continue;
    const double at = n[a] > 0 ? box.hi[a] : box.lo[a];
    return h->point[a] == at;
  }
  return false;
}

// The box the grid fills: the shape's bounds, except that a face of them that no plane of the
// shape lies in is where a curved surface touches it (a sphere's bounding box): the grid reaches
// a tenth of the box past it, or the hexes there would be slivers.
Aabb grid_box(const Shape& shape) {
  const Aabb tight = bounds(shape);
  if (!tight.is_finite()) throw Error("mesh by cuts: the shape is unbounded (a plane not intersected with a bounded shape)");
  if (tight.is_empty()) throw Error("mesh by cuts: the shape is empty (an intersection of disjoint bounding boxes)");
  Aabb box = tight;
  std::vector<Shape> all;
  collect(shape, 0, all);
  const double margin = 0.1 * (tight.hi - tight.lo).maxCoeff();
  for (int f = 0; f < 6; ++f) {
    const bool planar = std::any_of(all.begin(), all.end(), [&](const Shape& p) {
      const auto* hs = std::get_if<HalfSpace>(&p.node);
      return hs && is_face_of(p, tight) && hs->normal[f / 2] != 0 && (hs->normal[f / 2] > 0) == (f % 2 == 1);
    });
    if (!planar) (f % 2 ? box.hi : box.lo)[f / 2] += (f % 2 ? margin : -margin);
  }
  return box;
}

}  // namespace

std::vector<Shape> smooth_pieces(const Shape& shape, double reach) {
  std::vector<Shape> out;
  collect(shape, reach, out);
  return out;
}

CsgMeshResult mesh_by_cuts(const Shape& shape, const CsgMeshOptions& options) {
  const Aabb box = grid_box(shape);
  const Vec3 size = box.hi - box.lo;
  double h = options.cell_size;
  if (!(h > 0)) {
    if (options.resolution < 1) throw Error("mesh by cuts: the resolution must be at least 1");
    h = size.maxCoeff() / options.resolution;
  }
  std::array<int, 3> n{};
  double points = 1;
  for (int a = 0; a < 3; ++a) {
    n[a] = std::max(1, static_cast<int>(std::lround(size[a] / h)));
    points *= n[a] + 1.0;
  }
  if (points > 2147483647.0) throw Error(fmt::format("mesh by cuts: a grid of {:.3g} points is too large", points));

  CsgMeshResult res;
  const HexMesh grid = box_mesh(n[0], n[1], n[2], box.lo, box.hi);
  res.grid_hexes = grid.hexes.size();
  for (const Shape& p : smooth_pieces(shape, size.norm()))
    if (is_face_of(p, box)) ++res.skipped_faces;
    else res.pieces.push_back(p);

  CutResult cr;
  if (res.pieces.empty()) {
    cr.mesh = grid;  // a box alone: the grid is the mesh
  } else {
    CutOptions co = options.cut;
    co.keep = CutKeep::both;
    co.skip_missing = true;
    co.scale = size.norm();
    cr = cut(grid, res.pieces, co);
  }
  res.steps = cr.steps;
  res.max_distance = cr.max_distance;

  // The hexes inside the shape, by their centroids (no hex straddles a piece), with the
  // pieces' faces on them; one solid, so no blocks.
  std::vector<std::uint8_t> inside(cr.mesh.hexes.size());
  for (Index h = 0; h < cr.mesh.num_hexes(); ++h) inside[h] = evaluate(shape, cr.mesh.centroid(h)) < 0;
  res.dropped_hexes = static_cast<std::size_t>(std::count(inside.begin(), inside.end(), 0));
  if (res.dropped_hexes == inside.size())
    throw Error("mesh by cuts: no hex of the grid is inside the shape; use a smaller cell size");
  res.mesh = keep_hexes(cr.mesh, inside);
  res.mesh.blocks.clear();
  return res;
}

}  // namespace isohex
