#pragma once
/// \file abaqus.hpp
/// \brief How the Abaqus writer spells a real number: CalculiX reads each number of a data
/// line from its first 20 characters (and refuses a longer field), so every field the
/// writer puts on a data line fits in kAbaqusFieldWidth characters.

#include <cstddef>
#include <string>

namespace isohex::io {

/// The widest field of an Abaqus data line that CalculiX reads (its `f20.0` input format).
inline constexpr std::size_t kAbaqusFieldWidth = 20;

/// The finite `x` in at most kAbaqusFieldWidth characters, with as many significant digits
/// as fit: `%.17g` when it fits, else the exact integer for 1e17 <= |x| < 1e19 (1e20 when
/// positive), else the correct rounding to the largest precision p <= 17 that fits, as
/// `%.{p}g` or shortened (no 0 before the point, "e-7" for "e-07", "e17" for "e+17"). It
/// reads back exactly whenever some spelling of x of at most 17 digits fits (a rounding to p
/// >= the digits of x's shortest exact decimal is exact); otherwise p >= 13 for every double
/// and the error at most half a unit in the p-th digit. Never a string that reads back as
/// infinity (a rounding up past the largest double takes one digit fewer).
std::string abaqus_real(double x);

}  // namespace isohex::io
