#pragma once
// Each subcommand lives in its own file and registers itself on the root CLI::App.
// A registered callback runs the command; errors propagate as isohex::Error and main()
// prints them and exits non-zero.

#include <CLI/CLI.hpp>

namespace isohex::cli {

void register_quality(CLI::App& app);
void register_check(CLI::App& app);
void register_cut(CLI::App& app);
void register_convert(CLI::App& app);
void register_generate(CLI::App& app);
void register_mesh(CLI::App& app);
void register_pillow(CLI::App& app);
void register_refine(CLI::App& app);
void register_sheets(CLI::App& app);
void register_smooth(CLI::App& app);

/// The exit code a command asks for (0 unless a command reports a failed check).
int& exit_code();

}  // namespace isohex::cli

#include "isohex/volume/volume_io.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/quality/summary.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace isohex::cli {

/// How to read a volume (`isohex volume info|convert`, `isohex cut --volume`): the layout of
/// headerless raw files and the memory limit.
struct VolumeReadArgs {
  std::vector<Index> dims;
  std::string type, endian = "little";
  std::vector<double> spacing, origin;
  std::size_t header_bytes = 0;
  std::size_t max_memory = VolumeReadOptions{}.max_bytes;

  /// Adds --dims --type --endian --spacing --origin --header-bytes --max-memory.
  void add_to(CLI::App* cmd);
  /// The reader's options; throws isohex::Error for a partial raw layout.
  [[nodiscard]] VolumeReadOptions options() const;
};

/// Reads a mesh for a command; prints how many non-hex cells were dropped, if any.
HexMesh load_mesh(const std::string& file, bool skip_non_hex);

/// Writes a mesh a command made: a .vtu, .vtk or Exodus file carries each hex's quality
/// (io::quality_fields: "scaled_jacobian", "jacobian_ratio"), so that a viewer colours the worst
/// hexes without recomputing them.
void write_result(const std::string& file, const HexMesh& mesh);
/// The same with the quality a command has already computed (`cell_fields`) and `point_fields`;
/// the other formats have no place for them.
void write_result(const std::string& file, const HexMesh& mesh, std::vector<io::DataField> cell_fields,
                  std::vector<io::DataField> point_fields = {});

/// Min, mean, inverted, below 0.2 and degenerate of a scaled-Jacobian summary (the reports of
/// `isohex smooth` and `isohex cut`).
nlohmann::json quality_json(const MetricSummary& s);

/// Writes `json` (indented) to `file`, atomically.
void write_json(const std::string& file, const nlohmann::json& json);

/// Fails before any work if `file` is not a writable volume format (.nrrd, .vti).
void require_volume_output(const std::string& file);

/// Adds `--threads N` (0 = all cores) and returns where its value goes.
int* add_threads_option(CLI::App* cmd);

/// Limits oneTBB to `threads` workers for the lifetime of the returned object (0 = no limit).
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  void* control_ = nullptr;
};

}  // namespace isohex::cli

namespace isohex::cli {
/// `isohex volume`: creates the group and adds info/convert, then the two below.
void register_volume(CLI::App& app);
void register_volume_molecule(CLI::App& volume);
void register_volume_shape(CLI::App& volume);
}  // namespace isohex::cli
