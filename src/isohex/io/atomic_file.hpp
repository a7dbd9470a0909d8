#pragma once
/// \file atomic_file.hpp
/// \brief Write-to-temporary-then-rename, so that no reader ever sees a half-written file.

#include <filesystem>
#include <functional>
#include <iosfwd>
#include <string>

namespace isohex::io {

/// Calls `write` with a binary stream on a temporary file in the target's folder, flushes
/// it, and renames it onto `target`. If `write` throws or the stream fails, the temporary
/// file is removed, the target is left as it was, and isohex::Error (or the exception from
/// `write`) propagates.
void write_atomically(const std::filesystem::path& target,
                      const std::function<void(std::ostream&)>& write);

/// Reads a whole file into memory; throws isohex::Error naming the file if it cannot.
std::string read_file(const std::filesystem::path& file);

}  // namespace isohex::io
