#pragma once
/// \file interpolate.hpp
/// \brief Values between grid points: trilinear interpolation and its gradient, and the
/// inside/outside convention that turns a volume and an isovalue into a solid.
///
/// For the smoother cubic B-spline (interpolating or smoothing), see bspline.hpp.

#include "isohex/volume/volume.hpp"

#include <optional>
#include <string_view>

namespace isohex {

/// Which side of the isovalue is the solid.
///
/// The default is `above`: a point is inside when its value is greater than the isovalue,
/// as for bone in CT (high attenuation), densities and probability maps. Use `below` for
/// signed distance fields and other functions that are negative inside. A value exactly
/// at the isovalue is on the surface, neither inside nor outside.
enum class Inside : unsigned char { above, below };

/// "above" or "below".
std::string_view inside_name(Inside inside);
/// The Inside named "above" or "below", if any.
std::optional<Inside> inside_from_name(std::string_view name);

/// A level-set value that is positive inside, negative outside and zero on the surface:
/// `value - isovalue` for Inside::above, `isovalue - value` for Inside::below.
inline double inside_level(double value, double isovalue, Inside inside) {
  return inside == Inside::above ? value - isovalue : isovalue - value;
}

/// True when `value` is strictly on the inside of `isovalue`.
inline bool is_inside(double value, double isovalue, Inside inside) {
  return inside_level(value, isovalue, inside) > 0;
}

/// The continuous grid coordinates (i, j, k) of world point `p`: grid point (i, j, k) of
/// `volume` sits at `p` when they are integers.
Vec3 grid_coordinates(const Volume& volume, const Vec3& p);

/// The trilinear interpolant of `volume` at world point `p`.
///
/// It reproduces the grid values at grid points and any linear function of position
/// exactly. Points outside the grid's box take the value at the nearest point of the box
/// (the grid is clamped), and an axis with a single grid point is constant along it.
double sample(const Volume& volume, const Vec3& p);

/// The gradient (in world units) of the trilinear interpolant at world point `p`.
///
/// Within a cell it is the exact derivative of the interpolant; on a face between two cells
/// the cell on the upper side is used (the lower one on the grid's last face). Outside the box
/// the component along each clamped axis is 0, as for the clamped value.
Vec3 gradient(const Volume& volume, const Vec3& p);

/// Value and gradient at once (one cell lookup).
double sample(const Volume& volume, const Vec3& p, Vec3& gradient);

}  // namespace isohex
