// Legacy VTK writer: version 4.2 layout ("CELLS n 9n" with "8 i0 ... i7" records), which
// every VTK since 4.2 and most other tools read. BINARY is big-endian with double points
// (exact); ASCII prints 17 significant digits, which also round-trips doubles exactly.

#include "isohex/io/atomic_file.hpp"
#include "isohex/io/format_support.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/io/vtk_legacy_types.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <ostream>

namespace isohex::io {

namespace {

void write_header(std::ostream& out, bool binary) {
  out << "# vtk DataFile Version 4.2\nisohex hex mesh\n"
      << (binary ? "BINARY" : "ASCII") << "\nDATASET UNSTRUCTURED_GRID\n";
}

void write_binary(std::ostream& out, const HexMesh& mesh, const WriteOptions& options) {
  write_header(out, true);
  BigEndianOut be(out);
  // Each array: its header line, the raw values, and the newline VTK's writer puts after them.
  const auto section = [&](const std::string& header, const auto& write_values) {
    out << header;
    write_values();
    be.flush();
    out << '\n';
  };
  section(fmt::format("POINTS {} double\n", mesh.points.size()), [&] {
    for (const Vec3& p : mesh.points) {
      be.put(p.x());
      be.put(p.y());
      be.put(p.z());
    }
  });
  section(fmt::format("CELLS {} {}\n", mesh.hexes.size(), 9 * mesh.hexes.size()), [&] {
    for (const Hex& h : mesh.hexes) {
      be.put(std::int32_t{8});
      for (const Index v : h) be.put(static_cast<std::int32_t>(v));
    }
  });
  section(fmt::format("CELL_TYPES {}\n", mesh.hexes.size()), [&] {
    for (std::size_t i = 0; i < mesh.hexes.size(); ++i) be.put(std::int32_t{vtk::kHexahedron});
  });
  // CELL_DATA then POINT_DATA, each header once, then its arrays; the fields as one FIELD, which
  // VTK's reader reads whole (of several SCALARS it reads the first unless told otherwise).
  const auto fields = [&](const std::vector<DataField>& list) {
    if (list.empty()) return;
    out << fmt::format("FIELD FieldData {}\n", list.size());
    for (const DataField& d : list)
      section(fmt::format("{} 1 {} double\n", d.name, d.values.size()), [&] {
        for (const double v : d.values) be.put(v);
      });
  };
  if (mesh.has_blocks() || !options.cell_fields.empty()) out << fmt::format("CELL_DATA {}\n", mesh.hexes.size());
  if (mesh.has_blocks())
    section("SCALARS block int 1\nLOOKUP_TABLE default\n", [&] {
      for (const Index b : mesh.blocks) be.put(static_cast<std::int32_t>(b));
    });
  fields(options.cell_fields);
  if (mesh.has_fixed() || !options.point_fields.empty()) out << fmt::format("POINT_DATA {}\n", mesh.points.size());
  if (mesh.has_fixed())
    section("SCALARS fixed unsigned_char 1\nLOOKUP_TABLE default\n", [&] {
      for (const std::uint8_t f : mesh.fixed) be.put(static_cast<std::uint8_t>(f ? 1 : 0));
    });
  fields(options.point_fields);
}

void write_ascii(std::ostream& out, const HexMesh& mesh, const WriteOptions& options) {
  write_header(out, false);
  TextOut text(out);
  text.print("POINTS {} double\n", mesh.points.size());
  for (const Vec3& p : mesh.points) text.print("{:.17g} {:.17g} {:.17g}\n", p.x(), p.y(), p.z());
  text.print("CELLS {} {}\n", mesh.hexes.size(), 9 * mesh.hexes.size());
  for (const Hex& h : mesh.hexes)
    text.print("8 {} {} {} {} {} {} {} {}\n", h[0], h[1], h[2], h[3], h[4], h[5], h[6], h[7]);
  text.print("CELL_TYPES {}\n", mesh.hexes.size());
  for (std::size_t i = 0; i < mesh.hexes.size(); ++i) text.print("{}\n", vtk::kHexahedron);
  const auto fields = [&](const std::vector<DataField>& list) {
    if (!list.empty()) text.print("FIELD FieldData {}\n", list.size());
    for (const DataField& d : list) {
      text.print("{} 1 {} double\n", d.name, d.values.size());
      for (const double v : d.values) text.print("{:.17g}\n", v);
    }
  };
  if (mesh.has_blocks() || !options.cell_fields.empty()) text.print("CELL_DATA {}\n", mesh.hexes.size());
  if (mesh.has_blocks()) {
    text.print("SCALARS block int 1\nLOOKUP_TABLE default\n");
    for (const Index b : mesh.blocks) text.print("{}\n", b);
  }
  fields(options.cell_fields);
  if (mesh.has_fixed() || !options.point_fields.empty()) text.print("POINT_DATA {}\n", mesh.points.size());
  if (mesh.has_fixed()) {
    text.print("SCALARS fixed unsigned_char 1\nLOOKUP_TABLE default\n");
    for (const std::uint8_t f : mesh.fixed) text.print("{}\n", f ? 1 : 0);
  }
  fields(options.point_fields);
  text.flush();
}

}  // namespace

void write_vtk_legacy(const std::filesystem::path& file, const HexMesh& mesh, const WriteOptions& options) {
  check_mesh_for_writing(file, mesh);
  check_fields_for_writing(file, mesh, options);
  write_atomically(file, [&](std::ostream& out) {
    if (options.binary)
      write_binary(out, mesh, options);
    else
      write_ascii(out, mesh, options);
  });
}

}  // namespace isohex::io
