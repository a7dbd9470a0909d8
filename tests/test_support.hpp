#pragma once
// Helpers shared by the tests: data paths, a scratch folder, generated meshes, running the CLI.

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/optimize/optimize.hpp"
#include "isohex/volume/volume.hpp"

#include <array>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace isohex::test {

/// `../shared/data/<rel>` (use ISOHEX_REQUIRE_SHARED_DATA() first in the test body).
std::filesystem::path shared_data(const std::string& rel);
/// True when the shared data folder exists.
bool have_shared_data();
/// `../shared/data/volumes/<file>`, read with the raw layout SOURCES.md gives for the raw ones
/// (cthead, headsq, bucky); other formats describe themselves.
Volume shared_volume(const std::string& file);
/// A fresh, empty scratch folder named after the running test.
std::filesystem::path scratch_dir();
/// An nx*ny*nz grid of unit-spaced hexes (spacing h), vertices numbered x fastest.
HexMesh grid_mesh(int nx, int ny, int nz, double h = 1.0);

/// An n^3 unit-spaced volume of 0 holding a 6^3 block of 1 (samples 1..6 on each axis), then
/// the listed samples set to the listed values (n >= 8).
Volume block_volume(Index n, const std::vector<std::pair<std::array<Index, 3>, float>>& set);

/// A piece of a real mesh from tests/data/<name> ('v x y z role' per vertex, role 0 held, 1 a
/// free interior vertex, 2 a boundary vertex; 'h' + 8 vertex ids per hex; 't' the hexes the
/// piece is for, into `targets`). Vertices of role 1 are free (HexMesh::fixed 0), those of
/// role 2 too with `boundary_free`.
HexMesh read_piece(const std::string& name, std::vector<Index>& targets, bool boundary_free = false);

/// improve_worst() with the single moves only (no joint moves, no walk), up to `passes`
/// passes on m's free vertices (fewer passes in the result: they stopped, no single move gains).
WorstResult stall_single_moves(HexMesh& m, int passes);

/// `isohex smooth` on the piece `name` (read_piece(), boundary vertices free, the others held
/// through `--fixed file`), shape stage off, with `extra` options: the count `worst.<key>` of
/// its JSON report (the run must exit 0).
std::size_t smooth_piece_count(const std::string& name, const std::string& extra, const std::string& key);
/// improve_worst() with the single moves only (no joint moves, no walk), up to `passes`
/// passes on m's free vertices (fewer passes in the result: they stopped, no single move gains).
WorstResult stall_single_moves(HexMesh& m, int passes);

/// `isohex smooth` on the piece with `option value` out of range: exit 2, the option named, no
/// output written.
void expect_smooth_refuses(const std::string& name, const std::string& option, const std::string& value);

/// The corners of the unit cube in VTK order.
std::array<Vec3, 8> unit_cube();
/// `path` in single quotes, for run_cli command lines.
std::string quote(const std::filesystem::path& path);
/// Runs the isohex CLI with `args` (a shell-quoted string); returns the exit code and
/// captures stdout+stderr into `output`.
int run_cli(const std::string& args, std::string* output = nullptr);

}  // namespace isohex::test

/// Skips the calling test when ../shared/data is absent.
#define ISOHEX_REQUIRE_SHARED_DATA() \
  do {                                                                        \
    if (!::isohex::test::have_shared_data()) GTEST_SKIP() << "no shared data"; \
  } while (0)
