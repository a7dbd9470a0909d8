#pragma once
/// \file handle_move.hpp
/// \brief Internal to the manifold repair (manifold_repair.cpp): tunnel moves.

#include "isohex/contour/repair_internal.hpp"

#include <cstddef>

namespace isohex::contour {

/// A tunnel move for non-manifold `cell`: a corner x of the cell whose flip changes the genus
/// by one (closes or makes a tunnel or handle: topological numbers {1, 2} or {2, 1}, the two
/// local parts it joins or separates connected within 4 samples without it), then a point y
/// within 2 samples of x whose flip changes it back, both next to the isosurface, that
/// together lower the number of non-manifold cells around them: of all such pairs the one
/// leaving the fewest, then the lowest |level| sum (ties: grid order). A tunnel moved:
/// components and Euler characteristic kept. Applies it and returns true, with the points
/// flipped in `first` and `second`; false when there is none.
bool move_tunnel(SampledGrid& g, std::size_t cell, std::size_t& first, std::size_t& second);

}  // namespace isohex::contour
