// VTK XML UnstructuredGrid (.vtu): reading VTK's layouts, bit-exact round trips in every
// write mode, and malformed input that must fail with isohex::Error naming the file.
#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/mesh/generate.hpp"
#include "isohex/quality/hex_quality.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

using namespace isohex;
using isohex::test::grid_mesh;
using isohex::test::scratch_dir;
namespace fs = std::filesystem;

namespace {

void write_text(const fs::path& file, std::string_view text) {
  // Removing first: on ext4, truncating a file that has data forces a flush to disk, which
  // makes the thousands of rewrites below a hundred times slower.
  fs::remove(file);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  ASSERT_TRUE(out.good()) << file;
}

HexMesh read(const fs::path& file, io::ReadReport* report = nullptr, bool skip_non_hex = false) {
  io::ReadOptions options;
  options.skip_non_hex = skip_non_hex;
  return io::read_vtu(file, options, report);
}

/// Points compared bit for bit (so -0.0 differs from 0.0), everything else exactly.
void expect_same(const HexMesh& a, const HexMesh& b) {
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(std::bit_cast<std::uint64_t>(a.points[i][k]), std::bit_cast<std::uint64_t>(b.points[i][k]))
          << "point " << i << " coordinate " << k << ": " << a.points[i][k] << " vs " << b.points[i][k];
  EXPECT_EQ(a.hexes, b.hexes);
  EXPECT_EQ(a.blocks, b.blocks);
  EXPECT_EQ(a.fixed, b.fixed);
}

/// A grid with block ids, fixed flags and coordinates that text formats get wrong easily.
HexMesh awkward_mesh(int nx = 3, int ny = 2, int nz = 2) {
  HexMesh m = grid_mesh(nx, ny, nz, 1.0 / 3.0);
  m.points[0] = Vec3(1.0 / 3.0, 1e-300, -0.0);
  m.points[1] = Vec3(1e300, -1e300, std::numeric_limits<double>::max());
  m.points[2] = Vec3(std::numeric_limits<double>::min(), 0.1, -2.0 / 3.0);
  m.points[3] = Vec3(std::nextafter(1.0, 2.0), 123456789.123456789, -1e-17);
  for (Index h = 0; h < m.num_hexes(); ++h) m.blocks.push_back(h % 3 == 0 ? -7 : h * 1000003);
  m.fixed.assign(m.points.size(), 0);
  for (std::size_t i = 0; i < m.fixed.size(); i += 3) m.fixed[i] = 1;
  return m;
}

struct Mode {
  const char* name;
  io::WriteOptions options;
  const char* format;  ///< expected ReadReport::format
};

const std::vector<Mode>& modes() {
  static const std::vector<Mode> m = {{"zlib", {true, true}, "VTK XML appended raw zlib UInt64"},
                                      {"raw", {true, false}, "VTK XML appended raw UInt64"},
                                      {"ascii", {false, false}, "VTK XML ascii"}};
  return m;
}

/// Expects read_vtu(file) to throw isohex::Error naming the file and containing `fault`.
void expect_read_error(const fs::path& file, const std::string& fault, bool skip_non_hex = false) {
  try {
    read(file, nullptr, skip_non_hex);
    ADD_FAILURE() << file << ": read succeeded, expected an error containing '" << fault << "'";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(fault), std::string::npos) << "expected '" << fault << "' in: " << msg;
  }
}

/// Reads a possibly corrupt file: must either throw isohex::Error naming it, or succeed.
/// Returns true if it succeeded (the mesh in `out`).
bool read_or_error(const fs::path& file, HexMesh& out) {
  try {
    out = read(file);
    return true;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << file << ": not an isohex::Error: " << e.what();
  }
  return false;
}

std::size_t appended_begin(const std::string& text) {
  const std::size_t tag = text.find("<AppendedData");
  return tag == std::string::npos ? tag : text.find('_', tag) + 1;
}

// ---- a hand-made writer for layouts isohex does not write (inline base64, BigEndian,
// UInt32 headers, Float32/Int32/Int16/Int8 arrays), independent of the library's writer.

std::string base64(std::string_view bytes) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t v = std::uint32_t(static_cast<unsigned char>(bytes[i])) << 16;
    if (i + 1 < bytes.size()) v |= std::uint32_t(static_cast<unsigned char>(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 2]);
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? k[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? k[v & 63] : '=';
  }
  return out;
}

struct Layout {
  std::string format;  ///< "binary", "appended raw" or "appended base64"
  bool big_endian;
  bool header64;
};

template <class T>
void put(std::string& s, T v, bool big_endian) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
  s.append(b, sizeof(T));
}

std::string handmade_vtu(const HexMesh& m, const Layout& l) {
  struct Arr {
    const char* section;
    const char* head;
    std::string bytes;
  };
  std::vector<Arr> arrays = {
      {"PointData", R"(type="Int8" Name="fixed")", {}},
      {"CellData", R"(type="Int16" Name="CellEntityIds")", {}},
      {"Points", R"(type="Float32" Name="Points" NumberOfComponents="3")", {}},
      {"Cells", R"(type="Int32" Name="connectivity")", {}},
      {"Cells", R"(type="Int32" Name="offsets")", {}},
      {"Cells", R"(type="UInt8" Name="types")", {}}};
  for (auto f : m.fixed) put(arrays[0].bytes, static_cast<std::int8_t>(f), l.big_endian);
  for (auto b : m.blocks) put(arrays[1].bytes, static_cast<std::int16_t>(b), l.big_endian);
  for (const Vec3& p : m.points)
    for (int k = 0; k < 3; ++k) put(arrays[2].bytes, static_cast<float>(p[k]), l.big_endian);
  for (const Hex& h : m.hexes)
    for (Index id : h) put(arrays[3].bytes, id, l.big_endian);
  for (Index h = 1; h <= m.num_hexes(); ++h) put(arrays[4].bytes, 8 * h, l.big_endian);
  arrays[5].bytes.assign(m.hexes.size(), '\x0c');
  std::string xml = std::string("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"") +
                    (l.big_endian ? "BigEndian" : "LittleEndian") + "\" header_type=\"" +
                    (l.header64 ? "UInt64" : "UInt32") + "\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"" +
                    std::to_string(m.points.size()) + "\" NumberOfCells=\"" + std::to_string(m.hexes.size()) + "\">\n";
  std::string appended;
  for (const char* section : {"PointData", "CellData", "Points", "Cells"}) {
    xml += std::string("<") + section + ">\n";
    for (const Arr& a : arrays) {
      if (std::strcmp(a.section, section) != 0) continue;
      if ((&a == &arrays[0] && !m.has_fixed()) || (&a == &arrays[1] && !m.has_blocks())) continue;
      std::string payload;
      if (l.header64)
        put(payload, std::uint64_t{a.bytes.size()}, l.big_endian);
      else
        put(payload, static_cast<std::uint32_t>(a.bytes.size()), l.big_endian);
      payload += a.bytes;
      if (l.format == "binary") {
        xml += std::string("<DataArray ") + a.head + " format=\"binary\">\n  " + base64(payload) + "\n</DataArray>\n";
      } else {
        xml += std::string("<DataArray ") + a.head + " format=\"appended\" offset=\"" +
               std::to_string(appended.size()) + "\"/>\n";
        appended += l.format == "appended raw" ? payload : base64(payload);
      }
    }
    xml += std::string("</") + section + ">\n";
  }
  xml += "</Piece>\n</UnstructuredGrid>\n";
  if (l.format != "binary")
    xml += std::string("<AppendedData encoding=\"") + (l.format == "appended raw" ? "raw" : "base64") + "\">\n_" +
           appended + "\n</AppendedData>\n";
  return xml + "</VTKFile>\n";
}

/// A one-piece ascii .vtu with the given cell arrays as text.
std::string ascii_vtu(int points, const std::string& coords, int cells, const std::string& conn,
                      const std::string& offsets, const std::string& types, const std::string& extra = {}) {
  return "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"" +
         std::to_string(points) + "\" NumberOfCells=\"" + std::to_string(cells) + "\">\n" + extra +
         "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">" + coords +
         "</DataArray></Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">" + conn +
         "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">" + offsets +
         "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">" + types +
         "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
}

const std::string kCubeCoords = "0 0 0  1 0 0  1 1 0  0 1 0  0 0 1  1 0 1  1 1 1  0 1 1";

}  // namespace

TEST(VtuRead, CanLoads) {
  ISOHEX_REQUIRE_SHARED_DATA();
  io::ReadReport report;
  const HexMesh m = read(test::shared_data("hexmeshes/can.vtu"), &report);
  EXPECT_EQ(m.num_vertices(), 6724);
  EXPECT_EQ(m.num_hexes(), 4800);
  EXPECT_EQ(report.format, "VTK XML appended raw UInt64");
  // The file records the range of the point norms (RangeMin/RangeMax of its Points array).
  double lo = INFINITY, hi = 0;
  for (const Vec3& p : m.points) {
    lo = std::min(lo, p.norm());
    hi = std::max(hi, p.norm());
  }
  EXPECT_NEAR(lo, 13.91877583, 1e-6);
  EXPECT_NEAR(hi, 20.203379753, 1e-6);
  std::vector<int> uses(m.points.size(), 0);
  for (const Hex& h : m.hexes)
    for (Index id : h) ++uses[static_cast<std::size_t>(id)];
  EXPECT_EQ(std::count(uses.begin(), uses.end(), 0), 0) << "every vertex belongs to a hex";
}

TEST(VtuRoundTrip, EveryModeIsBitExact) {
  const fs::path dir = scratch_dir();
  const HexMesh m = awkward_mesh();
  for (const Mode& mode : modes()) {
    SCOPED_TRACE(mode.name);
    const fs::path file = dir / (std::string(mode.name) + ".vtu");
    io::write_vtu(file, m, mode.options);
    io::ReadReport report;
    expect_same(m, read(file, &report));
    EXPECT_EQ(report.format, mode.format);
    // Through the extension dispatcher too.
    expect_same(m, io::read_mesh(file));
  }
}

TEST(VtuRoundTrip, ManyZlibBlocksAndNoOptionalArrays) {
  const fs::path dir = scratch_dir();
  HexMesh big = grid_mesh(40, 30, 20, 0.1);  // 1.5 MB of connectivity: 47 zlib blocks
  big.points[17].x() = -0.0;
  for (const Mode& mode : modes()) {
    SCOPED_TRACE(mode.name);
    io::write_vtu(dir / "big.vtu", big, mode.options);
    const HexMesh back = read(dir / "big.vtu");
    expect_same(big, back);
    EXPECT_FALSE(back.has_blocks());
    EXPECT_FALSE(back.has_fixed());
  }
}

TEST(VtuRoundTrip, EmptyMesh) {
  const fs::path dir = scratch_dir();
  for (const Mode& mode : modes()) {
    SCOPED_TRACE(mode.name);
    io::write_vtu(dir / "empty.vtu", HexMesh{}, mode.options);
    const HexMesh back = read(dir / "empty.vtu");
    EXPECT_TRUE(back.points.empty());
    EXPECT_TRUE(back.hexes.empty());
  }
}

TEST(VtuRead, HandmadeLayouts) {
  const fs::path dir = scratch_dir();
  HexMesh m = grid_mesh(3, 2, 1, 0.25);  // coordinates exact in Float32
  m.points[5] = Vec3(-0.0, 1.0f / 3.0f, -1e-30f);
  m.blocks = {3, -4, 5, 32767, -32768, 0};
  m.fixed.assign(m.points.size(), 0);
  m.fixed[2] = m.fixed[7] = 1;
  for (const char* format : {"binary", "appended raw", "appended base64"})
    for (bool big_endian : {false, true})
      for (bool header64 : {false, true}) {
        const Layout layout{format, big_endian, header64};
        SCOPED_TRACE(testing::Message() << format << (big_endian ? " BigEndian" : "") << (header64 ? " UInt64" : " UInt32"));
        write_text(dir / "h.vtu", handmade_vtu(m, layout));
        io::ReadReport report;
        expect_same(m, read(dir / "h.vtu", &report));
        EXPECT_EQ(report.format, std::string("VTK XML ") + format + (header64 ? " UInt64" : " UInt32") +
                                     (big_endian ? " BigEndian" : ""));
      }
}

TEST(VtuRead, PiecesAreConcatenated) {
  const fs::path dir = scratch_dir();
  const std::string piece = "<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">" +
                            kCubeCoords + "</DataArray></Points><Cells>"
                            "<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 1 2 3 4 5 6 7</DataArray>"
                            "<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">8</DataArray>"
                            "<DataArray type=\"Int32\" Name=\"types\" format=\"ascii\">12</DataArray></Cells>";
  write_text(dir / "p.vtu",
             "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid>"
             "<Piece NumberOfPoints=\"8\" NumberOfCells=\"1\"><CellData><DataArray type=\"Int32\" Name=\"block\" "
             "format=\"ascii\">4</DataArray></CellData>" + piece + "</Piece>"
             "<Piece NumberOfPoints=\"8\" NumberOfCells=\"1\">" + piece + "</Piece>"
             "</UnstructuredGrid></VTKFile>");
  io::ReadReport report;
  const HexMesh m = read(dir / "p.vtu", &report);
  ASSERT_EQ(m.num_vertices(), 16);
  ASSERT_EQ(m.num_hexes(), 2);
  EXPECT_EQ(m.hexes[1], (Hex{8, 9, 10, 11, 12, 13, 14, 15}));
  EXPECT_EQ(m.blocks, (std::vector<Index>{4, 0}));
  EXPECT_EQ(report.format, "VTK XML ascii (2 pieces)");
}

TEST(VtuRead, VoxelIsReorderedToHex) {
  const fs::path dir = scratch_dir();
  write_text(dir / "v.vtu", ascii_vtu(8, "0 0 0  1 0 0  0 1 0  1 1 0  0 0 1  1 0 1  0 1 1  1 1 1", 1,
                                      "0 1 2 3 4 5 6 7", "8", "11"));
  const HexMesh m = read(dir / "v.vtu");
  ASSERT_EQ(m.num_hexes(), 1);
  EXPECT_EQ(m.hexes[0], (Hex{0, 1, 3, 2, 4, 5, 7, 6}));
}

TEST(VtuRead, NonHexCellsFailOrAreSkipped) {
  const fs::path dir = scratch_dir();
  const std::string blocks = "<CellData><DataArray type=\"Int64\" Name=\"MaterialIds\" format=\"ascii\">5 9 "
                             "6</DataArray></CellData>";
  write_text(dir / "mixed.vtu", ascii_vtu(8, kCubeCoords, 3, "0 1 2 3 4 5 6 7  0 1 2 4  0 1 2 3 4 5 6 7",
                                          "8 12 20", "12 10 12", blocks));
  expect_read_error(dir / "mixed.vtu", "cell 1 is a tetrahedron (VTK type 10)");
  io::ReadReport report;
  const HexMesh m = read(dir / "mixed.vtu", &report, true);
  EXPECT_EQ(m.num_hexes(), 2);
  EXPECT_EQ(report.skipped_cells, 1u);
  EXPECT_EQ(m.blocks, (std::vector<Index>{5, 6}));
}

TEST(VtuRead, RejectsMalformedFiles) {
  const fs::path dir = scratch_dir();
  struct Case {
    const char* name;
    std::string text;
    const char* fault;
  };
  const std::string valid = ascii_vtu(8, kCubeCoords, 1, "0 1 2 3 4 5 6 7", "8", "12");
  auto replaced = [&](const std::string& from, const std::string& to, const std::string& from2 = {},
                      const std::string& to2 = {}) {
    std::string s = valid;
    s.replace(s.find(from), from.size(), to);
    if (!from2.empty()) s.replace(s.find(from2), from2.size(), to2);
    return s;
  };
  HexMesh cube = grid_mesh(1, 1, 1);
  cube.points[3].y() = std::nan("");
  const std::vector<Case> cases = {
      {"empty", "", "no XML element"},
      {"not_vtk", "<html></html>", "not a VTK XML file"},
      {"polydata", replaced("UnstructuredGrid\" version", "PolyData\" version"), "only UnstructuredGrid"},
      {"lz4", replaced("version=\"0.1\"", "compressor=\"vtkLZ4DataCompressor\""), "vtkZLibDataCompressor"},
      {"mismatched_tag", replaced("</Cells>", "</Cell>"), "does not match <Cells>"},
      {"unclosed", valid.substr(0, valid.size() - 12), "unexpected end of file inside <VTKFile>"},
      {"id_out_of_range", replaced("0 1 2 3 4 5 6 7", "0 1 2 3 4 5 6 8"), "refers to vertex 8"},
      {"negative_id", replaced("0 1 2 3 4 5 6 7", "0 1 2 3 4 -5 6 7"), "refers to vertex -5"},
      {"seven_vertices", replaced(">8<", ">7<", "0 1 2 3 4 5 6 7", "0 1 2 3 4 5 6"), "with 7 vertices"},
      {"offsets_decrease", ascii_vtu(8, kCubeCoords, 2, "0 1 2 3 4 5 6 7", "8 0", "12 12"), "must not decrease"},
      {"nan_ascii", replaced("1 1 1", "1 nan 1"), "finite number"},
      {"nan_binary", handmade_vtu(cube, {"appended raw", false, true}), "non-finite"},
      {"too_few_values", replaced("0 1 2 3 4 5 6 7", "00 01 02 03 04 05 06"), "ends after 7 of its 8 values"},
      {"too_many_values", replaced(">8<", "> 8 9 <"), "more than the 1 values"},
      {"huge_point_count", replaced("NumberOfPoints=\"8\"", "NumberOfPoints=\"2000000000\""), "room for at most"},
      {"over_index_limit", replaced("NumberOfPoints=\"8\"", "NumberOfPoints=\"3000000000\""), "exceeds"},
      {"bad_type", replaced("type=\"UInt8\"", "type=\"String\""), "unsupported type 'String'"},
      {"bad_cell_type", replaced(">12<", ">300<"), "not a VTK cell type"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path file = dir / (std::string(c.name) + ".vtu");
    write_text(file, c.text);
    expect_read_error(file, c.fault);
  }
}

TEST(VtuRead, RejectsBadBinaryData) {
  const fs::path dir = scratch_dir();
  HexMesh m = grid_mesh(2, 1, 1);
  m.fixed.assign(m.points.size(), 1);  // the first array: 4 + 12 bytes, 24 base64 characters
  const std::string inline64 = handmade_vtu(m, {"binary", false, false});
  const std::size_t data = inline64.find("format=\"binary\">\n  ") + 19;  // the first array's base64
  std::string bad_char = inline64;
  bad_char[data + 5] = '!';
  std::string bad_pad = inline64;
  bad_pad[data + 6] = '=';  // padding inside a group that goes on
  std::string short64 = inline64;
  short64.erase(data + 8, short64.find('\n', data) - data - 8);  // only 6 of the first array's bytes
  std::string huge_appended = handmade_vtu(m, {"appended raw", false, true});
  huge_appended.replace(huge_appended.find("NumberOfPoints=\"12\""), 19, "NumberOfPoints=\"1000000000\"");
  std::string bad_offset = handmade_vtu(m, {"appended raw", false, true});
  bad_offset.replace(bad_offset.find("offset=\"0\""), 10, "offset=\"99999\"");
  const std::vector<std::pair<std::string, const char*>> cases = {
      {bad_char, "invalid base64 character '!'"},
      {bad_pad, "after '=' padding"},
      {short64, "base64 text holds at most 5"},
      {huge_appended, "size header declares 144 bytes, but 3000000000 values of Float32 need 12000000000"},
      {bad_offset, "beyond the end of the appended data"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(i);
    const fs::path file = dir / ("bad" + std::to_string(i) + ".vtu");
    write_text(file, cases[i].first);
    expect_read_error(file, cases[i].second);
  }
}

TEST(VtuRead, LyingSizeHeadersAreCaught) {
  const fs::path dir = scratch_dir();
  HexMesh m = grid_mesh(2, 2, 2);
  m.fixed.assign(m.points.size(), 1);  // the first appended array: 27 bytes
  io::write_vtu(dir / "raw.vtu", m, {true, false});
  io::write_vtu(dir / "zlib.vtu", m, {true, true});
  const std::string raw = io::read_file(dir / "raw.vtu"), zlib = io::read_file(dir / "zlib.vtu");
  auto with_word = [](std::string s, std::size_t at, std::uint64_t v) {
    std::memcpy(s.data() + at, &v, 8);
    return s;
  };
  const std::size_t r0 = appended_begin(raw), z0 = appended_begin(zlib);
  const std::vector<std::tuple<std::string, std::string, const char*>> cases = {
      {"raw_more", with_word(raw, r0, 35), "size header declares 35 bytes"},
      {"raw_less", with_word(raw, r0, 19), "size header declares 19 bytes"},
      {"raw_huge", with_word(raw, r0, std::uint64_t{1} << 62), "size header declares"},
      {"zlib_many_blocks", with_word(zlib, z0, std::uint64_t{1} << 40), "more than the file can hold"},
      {"zlib_two_blocks", with_word(zlib, z0, 2), "zlib"},
      {"zlib_block_size", with_word(zlib, z0 + 8, 10), "larger than the block size"},
      {"zlib_last_size", with_word(zlib, z0 + 16, 20), "declares 20 uncompressed bytes"},
      {"zlib_last_size_big", with_word(zlib, z0 + 16, 40000), "larger than the block size"},
      {"zlib_csize_huge", with_word(zlib, z0 + 24, std::uint64_t{1} << 60), "compressed bytes"},
      {"zlib_csize_short", with_word(zlib, z0 + 24, 5), "zlib block 0 of 1"},
  };
  for (const auto& [name, text, fault] : cases) {
    SCOPED_TRACE(name);
    write_text(dir / (name + ".vtu"), text);
    expect_read_error(dir / (name + ".vtu"), fault);
  }
}

TEST(VtuRead, TruncatedFilesFailCleanly) {
  const fs::path dir = scratch_dir();
  const HexMesh m = awkward_mesh(2, 1, 1);  // small: every prefix of the file is tried
  for (const Mode& mode : modes()) {
    SCOPED_TRACE(mode.name);
    io::write_vtu(dir / "full.vtu", m, mode.options);
    const std::string full = io::read_file(dir / "full.vtu");
    // Data ends before the closing tags; cutting anywhere before that must fail.
    const std::size_t data_end = mode.options.binary ? full.rfind("\n  </AppendedData>") : full.rfind("</VTKFile>") + 10;
    int failed = 0;
    for (std::size_t cut = 0; cut < full.size(); ++cut) {
      const fs::path file = dir / "cut.vtu";
      write_text(file, std::string_view(full).substr(0, cut));
      HexMesh back;
      if (read_or_error(file, back)) {
        EXPECT_GE(cut, data_end) << "a file truncated to " << cut << " bytes was accepted";
        expect_same(m, back);
      } else {
        ++failed;
      }
    }
    EXPECT_GE(failed, static_cast<int>(data_end));
  }
}

TEST(VtuRead, CorruptZlibDataIsDetected) {
  const fs::path dir = scratch_dir();
  const HexMesh m = awkward_mesh();
  io::write_vtu(dir / "z.vtu", m, {true, true});
  const std::string full = io::read_file(dir / "z.vtu");
  const std::size_t begin = appended_begin(full), end = full.rfind("\n  </AppendedData>");
  ASSERT_LT(begin, end);
  // Each array's compressed blocks run from after its header to the next array's offset.
  std::vector<std::size_t> offsets;
  for (std::size_t at = full.find("offset=\""); at < begin; at = full.find("offset=\"", at + 1))
    offsets.push_back(begin + std::stoull(full.substr(at + 8)));
  offsets.push_back(end);
  int flipped = 0, unnoticed = 0;
  for (std::size_t a = 0; a + 1 < offsets.size(); ++a) {
    std::uint64_t nblocks;
    std::memcpy(&nblocks, full.data() + offsets[a], 8);
    for (std::size_t at = offsets[a] + 8 * (3 + nblocks); at < offsets[a + 1]; ++at, ++flipped) {
      std::string bad = full;
      bad[at] = static_cast<char>(bad[at] ^ 0x5a);
      const fs::path file = dir / "bad.vtu";
      write_text(file, bad);
      // Flipping the unused padding bits at the end of a deflate stream changes nothing, so
      // a successful read must return the original mesh.
      HexMesh back;
      if (read_or_error(file, back)) {
        ++unnoticed;
        expect_same(m, back);
      }
    }
  }
  EXPECT_GT(flipped, 200);
  EXPECT_LT(unnoticed, flipped / 20);
}

TEST(VtuWrite, FailedWriteLeavesNoFile) {
  const fs::path dir = scratch_dir();
  HexMesh bad_id = awkward_mesh();
  bad_id.hexes.back()[5] = bad_id.num_vertices();
  HexMesh bad_point = awkward_mesh();
  bad_point.points.back().z() = INFINITY;
  for (const Mode& mode : modes())
    for (const HexMesh* m : {&bad_id, &bad_point}) {
      SCOPED_TRACE(mode.name);
      const fs::path file = dir / "out.vtu";
      try {
        io::write_vtu(file, *m, mode.options);
        ADD_FAILURE() << "writing an invalid mesh succeeded";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
      }
      EXPECT_TRUE(fs::is_empty(dir)) << "a failed write left a file behind";
    }
  // A failed write leaves an existing file untouched.
  io::write_vtu(dir / "out.vtu", grid_mesh(1, 1, 1), {});
  const std::string before = io::read_file(dir / "out.vtu");
  EXPECT_THROW(io::write_vtu(dir / "out.vtu", bad_id, {}), Error);
  EXPECT_EQ(io::read_file(dir / "out.vtu"), before);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

// Fields written beside the mesh (.vtu and .vtk, binary and ASCII; Exodus variables): the readers skip them and
// read the same mesh; a field that does not fit the mesh is refused before anything is written.
TEST(MeshFields, WrittenBesideTheMeshAndSkippedByTheReaders) {
  const fs::path dir = scratch_dir();
  HexMesh m = box_mesh(3, 2, 2);
  jitter(m, 0.02, 5);
  m.blocks.assign(m.hexes.size(), 4);
  io::WriteOptions o;
  o.cell_fields = io::quality_fields(m);
  ASSERT_EQ(o.cell_fields.size(), 2u);
  EXPECT_EQ(o.cell_fields[0].name, "scaled_jacobian");
  for (Index h = 0; h < m.num_hexes(); ++h) EXPECT_EQ(o.cell_fields[0].values[h], scaled_jacobian(m.corners(h)));
  o.point_fields = {{"height", {}}};
  for (const Vec3& p : m.points) o.point_fields[0].values.push_back(p.z());
  for (const bool binary : {true, false})
    for (const char* ext : {".vtu", ".vtk", ".exo"}) {
      SCOPED_TRACE(std::string(ext) + (binary ? " binary" : " ascii"));
      o.binary = binary;
      const fs::path f = dir / (std::string("fields") + (binary ? "_b" : "_a") + ext);
      io::write_mesh(f, m, o);
      const HexMesh back = io::read_mesh(f);
      EXPECT_EQ(back.hexes, m.hexes);
      EXPECT_EQ(back.blocks, m.blocks);
      ASSERT_EQ(back.points.size(), m.points.size());
      for (std::size_t v = 0; v < m.points.size(); ++v) EXPECT_EQ(back.points[v], m.points[v]);
    }
  const auto refused = [&](io::WriteOptions bad, const std::string& says) {
    const fs::path f = dir / "refused.vtu";
    fs::remove(f);
    try {
      io::write_mesh(f, m, bad);
      ADD_FAILURE() << "no error for " << says;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("refused.vtu"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(f));
  };
  io::WriteOptions bad = o;
  bad.cell_fields[1].values.pop_back();
  refused(bad, "has 11 values for 12 hexes");
  bad = o;
  bad.point_fields[0].name = "two words";
  refused(bad, "is not letters, digits and '_'");
  bad = o;
  bad.cell_fields[0].name = "block";
  refused(bad, "two arrays named 'block'");
}
