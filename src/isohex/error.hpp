#pragma once
/// \file error.hpp
/// \brief The one exception type isohex throws for bad input and impossible requests.
///
/// Messages name the file, the place (line, byte offset or element id) and what is wrong,
/// so that the CLI can print them as they are and exit non-zero.

#include <stdexcept>
#include <string>

namespace isohex {

/// Thrown for invalid input data or options. `what()` is a complete, user-facing message.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace isohex
