#pragma once
/// \file mesh_io.hpp
/// \brief Reading and writing hex meshes, the format chosen by the file extension.
///
/// | extension      | format                                                        |
/// |----------------|---------------------------------------------------------------|
/// | `.vtk`         | legacy VTK UNSTRUCTURED_GRID, ASCII or BINARY, 4.2 and 5.1    |
/// | `.vtu`         | VTK XML UnstructuredGrid: ascii, base64 inline, appended raw, zlib |
/// | `.mesh`        | MEDIT / GMF ASCII (Vertices, Hexahedra, references)           |
/// | `.inp`         | Abaqus input (C3D8 and its variants C3D8R, C3D8I, C3D8H, ...)  |
/// | `.exo` `.e` `.ex2` | Exodus II (HEX8 element blocks, boundary side set and node set) |
/// | `.msh`         | Gmsh 4.1, ASCII or binary (physical volumes per block, "boundary" surface) |
///
/// Every reader throws isohex::Error naming the file, the place (line or byte offset) and
/// the fault; it never crashes or hangs on malformed input, and refuses declared counts
/// that the file cannot hold. Every writer writes to a temporary file beside the target
/// and renames it into place, so a failed write leaves no half-written output.

#include "isohex/mesh/hex_mesh.hpp"

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace isohex::io {

/// Options shared by all readers.
struct ReadOptions {
  /// Drop cells that are not linear hexahedra (and count them) instead of failing.
  bool skip_non_hex = false;
};

/// What a reader noticed besides the mesh.
struct ReadReport {
  std::string format;               ///< e.g. "VTK legacy 5.1 binary"
  std::size_t skipped_cells = 0;    ///< non-hex cells dropped under skip_non_hex
};

/// An array of values written beside the mesh, one per hex (a cell field) or per vertex (a
/// point field): the quality of each hex, which vertices lie on the isosurface. The readers
/// skip them (the mesh is what they read).
struct DataField {
  std::string name;            ///< letters, digits and '_', starting with a letter
  std::vector<double> values;  ///< one per hex, or one per vertex
};

/// Options shared by all writers (each writer uses those that apply to it).
struct WriteOptions {
  bool binary = true;     ///< .vtk/.vtu: binary (exact) rather than ASCII (17 significant digits)
  bool compress = true;   ///< .vtu: zlib-compress the appended data, as VTK does by default
  bool msh_binary = false; ///< .msh: Gmsh's binary variant rather than ASCII (17 significant digits)
  /// .vtu / .vtk: CellData arrays after the block ids (Float64, one value per hex); Exodus:
  /// element variables at one time step (0).
  std::vector<DataField> cell_fields;
  /// .vtu / .vtk: PointData arrays after the fixed flags (Float64, one value per vertex); Exodus:
  /// nodal variables.
  std::vector<DataField> point_fields;
};

/// The quality of each hex as cell fields for WriteOptions::cell_fields: "scaled_jacobian"
/// (Verdict's: the corners and the centre) and "jacobian_ratio" (Gmsh's min det J / max det J
/// over the whole hex, certified: jacobian_ratio() of quality/jacobian_bounds.hpp; <= 0 where
/// the hex is not valid inside).
std::vector<DataField> quality_fields(const HexMesh& mesh);
/// The same from values already computed: scaled_jacobians() and mesh_jacobians().ratio.
std::vector<DataField> quality_fields(std::vector<double> scaled_jacobians, std::vector<double> jacobian_ratios);

/// Reads a mesh, choosing the reader by extension (case-insensitive).
HexMesh read_mesh(const std::filesystem::path& file, const ReadOptions& options = {},
                  ReadReport* report = nullptr);

/// Writes a mesh, choosing the writer by extension (case-insensitive).
void write_mesh(const std::filesystem::path& file, const HexMesh& mesh,
                const WriteOptions& options = {});

/// True if the extension of `file` names a format read_mesh/write_mesh know.
bool is_known_mesh_extension(const std::filesystem::path& file);
/// The extensions read_mesh/write_mesh know, for help texts and messages.
inline constexpr const char* kMeshExtensions = ".vtk .vtu .mesh .inp .exo .e .ex2 .msh";

// Per-format entry points (same contracts as above).
HexMesh read_vtk_legacy(const std::filesystem::path& file, const ReadOptions& options, ReadReport* report);
void write_vtk_legacy(const std::filesystem::path& file, const HexMesh& mesh, const WriteOptions& options);
HexMesh read_vtu(const std::filesystem::path& file, const ReadOptions& options, ReadReport* report);
void write_vtu(const std::filesystem::path& file, const HexMesh& mesh, const WriteOptions& options);
HexMesh read_medit(const std::filesystem::path& file, const ReadOptions& options, ReadReport* report);
void write_medit(const std::filesystem::path& file, const HexMesh& mesh, const WriteOptions& options);
HexMesh read_abaqus(const std::filesystem::path& file, const ReadOptions& options, ReadReport* report);
void write_abaqus(const std::filesystem::path& file, const HexMesh& mesh, const WriteOptions& options);
HexMesh read_exodus(const std::filesystem::path& file, const ReadOptions& options, ReadReport* report);
void write_exodus(const std::filesystem::path& file, const HexMesh& mesh, const WriteOptions& options);
HexMesh read_gmsh(const std::filesystem::path& file, const ReadOptions& options, ReadReport* report);
void write_gmsh(const std::filesystem::path& file, const HexMesh& mesh, const WriteOptions& options);

}  // namespace isohex::io
