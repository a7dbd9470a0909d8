#include "isohex/io/mesh_io.hpp"

#include "isohex/error.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "isohex/quality/jacobian_bounds.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

namespace isohex::io {

namespace {

enum class Format { vtk, vtu, medit, abaqus, exodus, gmsh, unknown };

Format format_of(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".vtk") return Format::vtk;
  if (ext == ".vtu") return Format::vtu;
  if (ext == ".mesh") return Format::medit;
  if (ext == ".inp") return Format::abaqus;
  if (ext == ".exo" || ext == ".e" || ext == ".ex2") return Format::exodus;
  if (ext == ".msh") return Format::gmsh;
  return Format::unknown;
}

[[noreturn]] void unknown_format(const std::filesystem::path& file) {
  throw Error(fmt::format("{}: unknown mesh format '{}' (known: .vtk .vtu .mesh .inp .exo .e .ex2 .msh)", file.string(),
                          file.extension().string()));
}

}  // namespace

bool is_known_mesh_extension(const std::filesystem::path& file) { return format_of(file) != Format::unknown; }

HexMesh read_mesh(const std::filesystem::path& file, const ReadOptions& options, ReadReport* report) {
  ReadReport local;
  ReadReport* r = report ? report : &local;
  switch (format_of(file)) {
    case Format::vtk: return read_vtk_legacy(file, options, r);
    case Format::vtu: return read_vtu(file, options, r);
    case Format::medit: return read_medit(file, options, r);
    case Format::abaqus: return read_abaqus(file, options, r);
    case Format::exodus: return read_exodus(file, options, r);
    case Format::gmsh: return read_gmsh(file, options, r);
    case Format::unknown: break;
  }
  unknown_format(file);
}

void write_mesh(const std::filesystem::path& file, const HexMesh& mesh, const WriteOptions& options) {
  switch (format_of(file)) {
    case Format::vtk: return write_vtk_legacy(file, mesh, options);
    case Format::vtu: return write_vtu(file, mesh, options);
    case Format::medit: return write_medit(file, mesh, options);
    case Format::abaqus: return write_abaqus(file, mesh, options);
    case Format::exodus: return write_exodus(file, mesh, options);
    case Format::gmsh: return write_gmsh(file, mesh, options);
    case Format::unknown: break;
  }
  unknown_format(file);
}

std::vector<DataField> quality_fields(std::vector<double> scaled_jacobians, std::vector<double> jacobian_ratios) {
  return {{"scaled_jacobian", std::move(scaled_jacobians)}, {"jacobian_ratio", std::move(jacobian_ratios)}};
}

std::vector<DataField> quality_fields(const HexMesh& mesh) {
  return quality_fields(scaled_jacobians(mesh), mesh_jacobians(mesh).ratio);
}

}  // namespace isohex::io
