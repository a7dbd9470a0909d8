// Pieces the subcommands share: loading a mesh, the thread limit.
#include "commands.hpp"

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"

#include <fmt/format.h>
#include <tbb/global_control.h>

#include <cctype>
#include <filesystem>
#include <ostream>

namespace isohex::cli {

HexMesh load_mesh(const std::string& file, bool skip_non_hex) {
  io::ReadOptions opt;
  opt.skip_non_hex = skip_non_hex;
  io::ReadReport report;
  HexMesh mesh = io::read_mesh(file, opt, &report);
  if (report.skipped_cells)
    fmt::print("{}: skipped {} non-hexahedral cells (--skip-non-hex)\n", file, report.skipped_cells);
  return mesh;
}

nlohmann::json quality_json(const MetricSummary& s) {
  return {{"min", s.min},
          {"mean", s.mean},
          {"inverted", s.inverted},
          {"below_0.2", s.inverted + s.questionable + s.degenerate},
          {"degenerate", s.degenerate}};
}

void write_json(const std::string& file, const nlohmann::json& json) {
  io::write_atomically(file, [&](std::ostream& os) { os << json.dump(2) << '\n'; });
}

void require_volume_output(const std::string& file) {
  std::string ext = std::filesystem::path(file).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".nrrd" && ext != ".vti")
    throw Error(fmt::format("{}: cannot write volume format '{}' (writable: .nrrd .vti)", file, ext));
}

int* add_threads_option(CLI::App* cmd) {
  auto* threads = new int(0);  // lives as long as the process: CLI11 keeps a pointer to it
  cmd->add_option("--threads", *threads, "Worker threads (0 = all cores); results do not depend on it")
      ->check(CLI::NonNegativeNumber);
  return threads;
}

ThreadLimit::ThreadLimit(int threads) {
  if (threads > 0)
    control_ = new tbb::global_control(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
}

ThreadLimit::~ThreadLimit() { delete static_cast<tbb::global_control*>(control_); }

}  // namespace isohex::cli
