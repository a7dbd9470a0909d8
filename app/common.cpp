// Pieces the subcommands share: loading a mesh, the thread limit.
#include "commands.hpp"

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/volume/volume_io.hpp"

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

namespace {

// .vtu and .vtk (arrays) and Exodus (element and nodal variables at one time step).
bool carries_fields(const std::string& file) {
  std::string ext = std::filesystem::path(file).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".vtu" || ext == ".vtk" || ext == ".exo" || ext == ".e" || ext == ".ex2";
}

}  // namespace

void write_result(const std::string& file, const HexMesh& mesh, std::vector<io::DataField> cell_fields,
                  std::vector<io::DataField> point_fields) {
  io::WriteOptions options;
  if (carries_fields(file)) {
    options.cell_fields = std::move(cell_fields);
    options.point_fields = std::move(point_fields);
  }
  io::write_mesh(file, mesh, options);
}

void write_result(const std::string& file, const HexMesh& mesh) {
  write_result(file, mesh, carries_fields(file) ? io::quality_fields(mesh) : std::vector<io::DataField>{});
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

void VolumeReadArgs::add_to(CLI::App* cmd) {
  cmd->add_option("--dims", dims, "Raw files: grid points along x, y, z")->expected(3);
  cmd->add_option("--type", type, "Raw files: the stored value type")
      ->check(CLI::IsMember({"u8", "i8", "u16", "i16", "u32", "i32", "f32", "f64"}));
  cmd->add_option("--endian", endian, "Raw files: byte order (default little)")->check(CLI::IsMember({"little", "big"}));
  cmd->add_option("--spacing", spacing, "Raw files: distance between grid points along x, y, z (default 1 1 1)")
      ->expected(3);
  cmd->add_option("--origin", origin, "Raw files: position of the first grid point (default 0 0 0)")->expected(3);
  cmd->add_option("--header-bytes", header_bytes, "Raw files: bytes to skip before the data (default 0)");
  cmd->add_option("--max-memory", max_memory,
                  "Refuse volumes whose float values need more than this many bytes (default 8GiB; "
                  "suffixes KiB, MiB, GiB, ...)")
      ->transform(CLI::AsSizeValue(false));
}

VolumeReadOptions VolumeReadArgs::options() const {
  VolumeReadOptions opt;
  opt.max_bytes = max_memory;
  const bool any_raw = !dims.empty() || !type.empty() || !spacing.empty() || !origin.empty() || header_bytes != 0;
  if (!any_raw) return opt;
  if (dims.empty() || type.empty()) throw Error("raw layout options need at least --dims NX NY NZ and --type");
  RawLayout raw;
  raw.dims = {dims[0], dims[1], dims[2]};
  raw.type = *scalar_type_from_name(type);
  raw.big_endian = endian == "big";
  if (!spacing.empty()) raw.spacing = Vec3(spacing[0], spacing[1], spacing[2]);
  if (!origin.empty()) raw.origin = Vec3(origin[0], origin[1], origin[2]);
  raw.header_bytes = header_bytes;
  opt.raw = raw;
  return opt;
}

}  // namespace isohex::cli
