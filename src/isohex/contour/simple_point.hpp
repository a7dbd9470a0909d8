#pragma once
/// \file simple_point.hpp
/// \brief Simple points of digital topology: grid points whose inside/outside flag can be
/// flipped without changing the topology of the solid or of its complement.
///
/// The mesher's solid has the topology that marching cubes gives the samples: inside points
/// are joined only through cell edges (6-adjacency: marching cubes separates inside corners
/// on ambiguous faces and body diagonals), outside points also across face diagonals
/// (18-adjacency: it joins outside corners across an ambiguous face but not through a cell's
/// body diagonal). A point is *simple* for this (6, 18) pair when flipping it changes no
/// component, tunnel or cavity of either set. The test is local, on the 26 neighbours, by
/// the topological numbers of Bertrand & Malandain (1994): T6+(x, X) = 1 and
/// T18(x, X̄) = 1, with the geodesic neighbourhoods N6³ and N18² inside the 26-neighbourhood.

#include <array>

namespace isohex::contour {

/// The 3×3×3 block around a point, `inside[x + 3y + 9z]` for offsets x, y, z ∈ {0, 1, 2}
/// (the point itself at 13; its own flag is ignored).
using Neighbourhood = std::array<bool, 27>;

/// True when the centre of `nb` is simple for (inside 6-adjacency, outside 18-adjacency).
[[nodiscard]] bool is_simple_6_18(const Neighbourhood& nb);

/// The topological numbers {T6+(x, X), T18(x, X̄)} of the centre of `nb` (is_simple_6_18 is
/// both being 1). A fill of an outside centre with {1, 2} closes a tunnel or makes a cavity,
/// a carve of an inside centre with {2, 1} opens a tunnel or cuts a component, depending on
/// whether the two local parts meet elsewhere.
[[nodiscard]] std::array<int, 2> topological_numbers_6_18(const Neighbourhood& nb);

}  // namespace isohex::contour
