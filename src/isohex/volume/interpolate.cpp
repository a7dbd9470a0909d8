#include "isohex/volume/interpolate.hpp"

#include <algorithm>
#include <cmath>

namespace isohex {

namespace {

/// The cell holding grid coordinate t along an axis of n points: its first point i0, the
/// local coordinate f in [0, 1], and whether t was clamped onto the axis.
struct AxisCell {
  Index i0 = 0;
  Index i1 = 0;  // i0 + 1, or i0 on an axis with one point
  double f = 0;
  bool clamped = false;
};

AxisCell axis_cell(double t, Index n) {
  AxisCell c;
  if (n <= 1 || !(t == t)) {  // a single point, or NaN: constant
    c.clamped = true;
    return c;
  }
  const double last = static_cast<double>(n - 1);
  if (t <= 0) {
    c.clamped = t < 0;
    t = 0;
  } else if (t >= last) {
    c.clamped = t > last;
    t = last;
  }
  c.i0 = std::min(static_cast<Index>(std::floor(t)), n - 2);
  c.i1 = c.i0 + 1;
  c.f = t - c.i0;
  return c;
}

}  // namespace

std::string_view inside_name(Inside inside) { return inside == Inside::above ? "above" : "below"; }

std::optional<Inside> inside_from_name(std::string_view name) {
  if (name == "above") return Inside::above;
  if (name == "below") return Inside::below;
  return std::nullopt;
}

Vec3 grid_coordinates(const Volume& volume, const Vec3& p) { return (p - volume.origin).cwiseQuotient(volume.spacing); }

double sample(const Volume& volume, const Vec3& p, Vec3& grad) {
  const Vec3 t = grid_coordinates(volume, p);
  const AxisCell cx = axis_cell(t.x(), volume.dims[0]);
  const AxisCell cy = axis_cell(t.y(), volume.dims[1]);
  const AxisCell cz = axis_cell(t.z(), volume.dims[2]);
  const double v000 = volume.at(cx.i0, cy.i0, cz.i0), v100 = volume.at(cx.i1, cy.i0, cz.i0);
  const double v010 = volume.at(cx.i0, cy.i1, cz.i0), v110 = volume.at(cx.i1, cy.i1, cz.i0);
  const double v001 = volume.at(cx.i0, cy.i0, cz.i1), v101 = volume.at(cx.i1, cy.i0, cz.i1);
  const double v011 = volume.at(cx.i0, cy.i1, cz.i1), v111 = volume.at(cx.i1, cy.i1, cz.i1);
  const double fx = cx.f, fy = cy.f, fz = cz.f;
  // Interpolate along x, then y, then z; the derivatives follow the same tree.
  const double a00 = v000 + fx * (v100 - v000), a10 = v010 + fx * (v110 - v010);
  const double a01 = v001 + fx * (v101 - v001), a11 = v011 + fx * (v111 - v011);
  const double b0 = a00 + fy * (a10 - a00), b1 = a01 + fy * (a11 - a01);
  const double value = b0 + fz * (b1 - b0);

  const double dx00 = v100 - v000, dx10 = v110 - v010, dx01 = v101 - v001, dx11 = v111 - v011;
  const double dx0 = dx00 + fy * (dx10 - dx00), dx1 = dx01 + fy * (dx11 - dx01);
  const double ddx = dx0 + fz * (dx1 - dx0);
  const double ddy = (a10 - a00) + fz * ((a11 - a01) - (a10 - a00));
  const double ddz = b1 - b0;
  grad = Vec3(cx.clamped ? 0.0 : ddx / volume.spacing.x(), cy.clamped ? 0.0 : ddy / volume.spacing.y(),
              cz.clamped ? 0.0 : ddz / volume.spacing.z());
  return value;
}

double sample(const Volume& volume, const Vec3& p) {
  Vec3 g;
  return sample(volume, p, g);
}

Vec3 gradient(const Volume& volume, const Vec3& p) {
  Vec3 g;
  sample(volume, p, g);
  return g;
}

}  // namespace isohex
