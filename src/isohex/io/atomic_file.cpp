#include "isohex/io/atomic_file.hpp"

#include "isohex/error.hpp"

#include <fmt/format.h>
#include <fmt/std.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace isohex::io {

namespace fs = std::filesystem;

void write_atomically(const fs::path& target, const std::function<void(std::ostream&)>& write) {
  static std::atomic<unsigned> counter{0};
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir))
    throw Error(fmt::format("{}: cannot write: folder {} does not exist", target.string(), dir.string()));
  const fs::path tmp = dir / fmt::format(".{}.tmp{}.{}", target.filename().string(), ::getpid(), counter++);
  try {
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      if (!out) throw Error(fmt::format("{}: cannot create temporary file: {}", target.string(), std::strerror(errno)));
      write(out);
      out.flush();
      if (!out) throw Error(fmt::format("{}: write failed (disk full?)", target.string()));
    }
    std::error_code ec;
    fs::rename(tmp, target, ec);
    if (ec) throw Error(fmt::format("{}: cannot rename temporary file into place: {}", target.string(), ec.message()));
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
}

std::string read_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot open: {}", file.string(), std::strerror(errno)));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw Error(fmt::format("{}: read error", file.string()));
  return std::move(ss).str();
}

}  // namespace isohex::io
