// Legacy VTK reader and writer: shared files, exact round trips, every skippable section in
// ASCII and binary, malformed input (each error naming the file and the place) and
// truncation at every offset.

#include "io_legacy_support.hpp"
#include "isohex/io/big_endian.hpp"

#include <chrono>

namespace isohex::test {
namespace {

using io::ReadOptions;
using io::ReadReport;
using io::WriteOptions;

// Two hexes sharing a face. Line 19 and 20 hold the cells, 22 and 23 their types.
constexpr const char* kTwoHexes = R"(# vtk DataFile Version 3.0
two hexes
ASCII
DATASET UNSTRUCTURED_GRID
POINTS 12 float
0 0 0
1 0 0
2 0 0
0 1 0
1 1 0
2 1 0
0 0 1
1 0 1
2 0 1
0 1 1
1 1 1
2 1 1
CELLS 2 18
8 0 1 4 3 6 7 10 9
8 1 2 5 4 7 8 11 10
CELL_TYPES 2
12
12
)";

HexMesh two_hexes() {
  HexMesh m = grid_mesh(2, 1, 1);
  return m;
}

/// Builds legacy files whose arrays are written either as ASCII numbers or as big-endian
/// bytes, so one description yields both variants.
class VtkBuilder {
 public:
  explicit VtkBuilder(bool binary, const std::string& version = "5.1") : binary_(binary) {
    text_ = "# vtk DataFile Version " + version + "\nbuilt by a test\n" + (binary ? "BINARY" : "ASCII") +
            "\nDATASET UNSTRUCTURED_GRID\n";
  }
  VtkBuilder& line(const std::string& text) {
    text_ += text + "\n";
    return *this;
  }
  template <class T>
  VtkBuilder& values(const std::vector<T>& v) {
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (binary_) {
        unsigned char b[sizeof(T)];
        io::store_be(b, v[i]);
        text_.append(reinterpret_cast<const char*>(b), sizeof(T));
      } else {
        text_ += (i ? " " : "") + fmt_value(v[i]);
      }
    }
    text_ += "\n";
    return *this;
  }
  VtkBuilder& bits(const std::vector<int>& v) {
    if (!binary_) return values(v);
    std::string packed((v.size() + 7) / 8, '\0');
    for (std::size_t i = 0; i < v.size(); ++i)
      if (v[i]) packed[i / 8] = static_cast<char>(packed[i / 8] | (0x80 >> (i % 8)));
    text_ += packed + "\n";
    return *this;
  }
  VtkBuilder& strings(const std::vector<std::string>& v) {
    for (const std::string& s : v) {
      if (binary_)
        text_ += static_cast<char>(0xC0 | s.size()) + s;  // the one-byte length form
      else
        text_ += s + "\n";
    }
    if (binary_) text_ += "\n";
    return *this;
  }
  [[nodiscard]] const std::string& str() const { return text_; }
  [[nodiscard]] std::size_t size() const { return text_.size(); }

 private:
  template <class T>
  static std::string fmt_value(T v) {
    if constexpr (std::is_floating_point_v<T>)
      return fmt::format("{:.17g}", v);
    else
      return std::to_string(+v);
  }
  bool binary_;
  std::string text_;
};

std::vector<double> coordinates(const HexMesh& m) {
  std::vector<double> c;
  for (const Vec3& p : m.points) c.insert(c.end(), {p.x(), p.y(), p.z()});
  return c;
}

/// A 5.1 file that uses every kind of section a reader must step over.
std::string every_section_file(bool binary) {
  const HexMesh m = two_hexes();
  const std::vector<std::uint8_t> fixed = {1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0};
  VtkBuilder b(binary);
  b.line("FIELD FieldData 2").line("TIME 1 1 double").values(std::vector<double>{0.5});
  b.line("names 1 2 string").strings({"first name", "second%20name"});
  b.line("POINTS 12 double").values(coordinates(m));
  b.line("METADATA")
      .line("INFORMATION 1")
      .line("NAME L2_NORM_RANGE LOCATION vtkDataArray")
      .line("DATA 2 0 1.7")
      .line("");
  b.line("CELLS 3 16").line("OFFSETS vtktypeint32").values(std::vector<std::int32_t>{0, 8, 16});
  b.line("METADATA").line("COMPONENT_NAMES").line("x").line("");
  std::vector<std::int64_t> conn;
  for (const Hex& h : m.hexes) conn.insert(conn.end(), h.begin(), h.end());
  b.line("CONNECTIVITY vtktypeint64").values(conn);
  b.line("CELL_TYPES 2").values(std::vector<std::int32_t>{12, 12});
  b.line("CELL_DATA 2").line("SCALARS pressure float 2").line("LOOKUP_TABLE default");
  b.values(std::vector<float>{1, 2, 3, 4});
  if (binary)
    b.line("LOOKUP_TABLE table 2").values(std::vector<std::uint8_t>{0, 0, 0, 255, 255, 255, 255, 255});
  else
    b.line("LOOKUP_TABLE table 2").values(std::vector<float>{0, 0, 0, 1, 1, 1, 1, 1});
  if (binary)
    b.line("COLOR_SCALARS colours 3").values(std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6});
  else
    b.line("COLOR_SCALARS colours 3").values(std::vector<float>{0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f});
  b.line("FIELD cellfield 2").line("CellEntityIds 1 2 int").values(std::vector<std::int32_t>{5, -7});
  b.line("flags 1 2 bit").bits({1, 0});
  b.line("POINT_DATA 12").line("VECTORS velocity double").values(std::vector<double>(36, -1.5));
  b.line("NORMALS normals float").values(std::vector<float>(36, 0.25f));
  b.line("TENSORS stress double").values(std::vector<double>(108, 3.0));
  b.line("TENSORS6 sym double").values(std::vector<double>(72, 4.0));
  b.line("TEXTURE_COORDINATES uv 2 float").values(std::vector<float>(24, 0.5f));
  b.line("GLOBAL_IDS ids vtkIdType").values(std::vector<std::int32_t>(12, 9));
  b.line("PEDIGREE_IDS pids long").values(std::vector<std::int64_t>(12, 11));
  b.line("SCALARS temperature short").line("LOOKUP_TABLE default").values(std::vector<std::int16_t>(12, -3));
  b.line("FIELD pointfield 3").line("labels 1 12 string");
  b.strings({"a", "b", "c", "d", "e", "f", "g", "h", "i", "j", "k", "l"});
  b.line("NULL_ARRAY").line("fixed 1 12 unsigned_char").values(fixed);
  return b.str();
}

TEST(VtkLegacy, SharedFilesLoadWithTheirCounts) {
  ISOHEX_REQUIRE_SHARED_DATA();
  ReadReport report;
  const HexMesh rockarm = io::read_mesh(shared_data("hexmeshes/rockarm.vtk"), {}, &report);
  EXPECT_EQ(report.format, "VTK legacy 3.0 ASCII");
  EXPECT_EQ(rockarm.num_vertices(), 2651);
  EXPECT_EQ(rockarm.num_hexes(), 1858);
  EXPECT_EQ(rockarm.points[0], Vec3(0.0811033, -0.104003, -0.233597));  // line 6 of the file
  EXPECT_EQ(rockarm.hexes[1], (Hex{9, 5, 4, 8, 11, 7, 6, 10}));         // line 2659
  EXPECT_FALSE(rockarm.has_blocks());
  EXPECT_FALSE(rockarm.has_fixed());

  struct Mesquite {
    const char* name;
    Index vertices, hexes;
    int fixed;  // nonzero entries of the file's `fixed` array, counted with Python
  };
  for (const Mesquite& q : {Mesquite{"hex_5_tangled.vtk", 216, 125, 152}, Mesquite{"pave1.e.vtk", 8722, 7110, 3039},
                            Mesquite{"pave2.e.vtk", 3408, 2704, 1304}, Mesquite{"pave3.e.vtk", 2385, 1791, 1092},
                            Mesquite{"pave_cyl.e.vtk", 3948, 3120, 1524}}) {
    const HexMesh m = io::read_mesh(shared_data(std::string("hexmeshes/mesquite/") + q.name));
    EXPECT_EQ(m.num_vertices(), q.vertices) << q.name;
    EXPECT_EQ(m.num_hexes(), q.hexes) << q.name;
    ASSERT_TRUE(m.has_fixed()) << q.name;
    EXPECT_EQ(std::count(m.fixed.begin(), m.fixed.end(), 1), q.fixed) << q.name;
  }
}

TEST(VtkLegacy, NotchFileHasFourWedges) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const fs::path notch = shared_data("hexmeshes/notch_stress_fixed.vtk");
  // CELL_TYPES data start at byte 242829; cell 1172 is the first wedge.
  expect_read_error(notch, {": byte 247517: ", "4 of 2192 cells are not hexahedra", "cell 1172 (wedge, VTK type 13)",
                            "cell 1173", "cell 1212", "cell 1213", "skip_non_hex"});
  ReadOptions skip;
  skip.skip_non_hex = true;
  ReadReport report;
  const HexMesh m = io::read_mesh(notch, skip, &report);
  EXPECT_EQ(report.format, "VTK legacy 5.1 binary");
  EXPECT_EQ(report.skipped_cells, 4u);
  EXPECT_EQ(m.num_vertices(), 3537);
  EXPECT_EQ(m.num_hexes(), 2188);
  // SOURCES.md: bounding box 0..0.4 x 0..0.1 x 0..0.01, which wrong byte order would break.
  for (const Vec3& p : m.points) {
    const double e = 1e-12;
    ASSERT_TRUE(p.x() >= -e && p.x() <= 0.4 + e && p.y() >= -e && p.y() <= 0.1 + e && p.z() >= -e && p.z() <= 0.01 + e)
        << p.transpose();
  }
}

TEST(VtkLegacy, RoundTripsAwkwardCoordinatesExactly) {
  const fs::path dir = scratch_dir();
  for (const bool binary : {true, false})
    for (const bool blocks : {false, true})
      for (const bool fixed : {false, true}) {
        SCOPED_TRACE(fmt::format("binary {} blocks {} fixed {}", binary, blocks, fixed));
        const HexMesh m = awkward_mesh(blocks, fixed);
        const fs::path file = dir / "m.vtk";
        WriteOptions w;
        w.binary = binary;
        io::write_mesh(file, m, w);
        ReadReport report;
        const HexMesh back = io::read_mesh(file, {}, &report);
        EXPECT_EQ(report.format, binary ? "VTK legacy 4.2 binary" : "VTK legacy 4.2 ASCII");
        expect_same_mesh(m, back);
        EXPECT_EQ(back.has_blocks(), blocks);
        EXPECT_EQ(back.has_fixed(), fixed);
      }
}

TEST(VtkLegacy, RoundTripsSharedFiles) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  ReadOptions skip;
  skip.skip_non_hex = true;
  for (const char* name :
       {"hexmeshes/rockarm.vtk", "hexmeshes/notch_stress_fixed.vtk", "hexmeshes/mesquite/pave1.e.vtk"}) {
    const HexMesh m = io::read_mesh(shared_data(name), skip);
    for (const bool binary : {true, false}) {
      SCOPED_TRACE(fmt::format("{} binary {}", name, binary));
      WriteOptions w;
      w.binary = binary;
      io::write_mesh(dir / "copy.vtk", m, w);
      expect_same_mesh(m, io::read_mesh(dir / "copy.vtk"));
    }
  }
}

TEST(VtkLegacy, SkipsEverySectionItDoesNotUse) {
  const fs::path dir = scratch_dir();
  for (const bool binary : {false, true}) {
    SCOPED_TRACE(binary ? "binary" : "ASCII");
    write_text(dir / "sections.vtk", every_section_file(binary));
    ReadReport report;
    const HexMesh m = io::read_mesh(dir / "sections.vtk", {}, &report);
    EXPECT_EQ(report.format, binary ? "VTK legacy 5.1 binary" : "VTK legacy 5.1 ASCII");
    HexMesh expected = two_hexes();
    expected.blocks = {5, -7};  // CellEntityIds
    expected.fixed = {1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0};
    expect_same_mesh(expected, m);
  }
}

TEST(VtkLegacy, ReadsPointsOfAnyNumericType) {
  const fs::path dir = scratch_dir();
  const HexMesh m = two_hexes();
  std::vector<std::int32_t> cells;
  for (const Hex& h : m.hexes) {
    cells.push_back(8);
    cells.insert(cells.end(), h.begin(), h.end());
  }
  const std::vector<double> c = coordinates(m);
  for (const bool binary : {false, true}) {
    SCOPED_TRACE(binary ? "binary" : "ASCII");
    const auto check = [&](const std::string& type, const auto& values) {
      VtkBuilder b(binary, "4.2");
      b.line("POINTS 12 " + type).values(values).line("CELLS 2 18").values(cells);
      b.line("CELL_TYPES 2").values(std::vector<std::int32_t>{12, 12});
      write_text(dir / "points.vtk", b.str());
      SCOPED_TRACE(type);
      expect_same_mesh(m, io::read_mesh(dir / "points.vtk"));
    };
    check("unsigned_char", std::vector<std::uint8_t>(c.begin(), c.end()));
    check("char", std::vector<std::int8_t>(c.begin(), c.end()));
    check("short", std::vector<std::int16_t>(c.begin(), c.end()));
    check("unsigned_short", std::vector<std::uint16_t>(c.begin(), c.end()));
    check("int", std::vector<std::int32_t>(c.begin(), c.end()));
    check("unsigned_int", std::vector<std::uint32_t>(c.begin(), c.end()));
    check("vtktypeint64", std::vector<std::int64_t>(c.begin(), c.end()));
    check("unsigned_long", std::vector<std::uint64_t>(c.begin(), c.end()));
    check("float", std::vector<float>(c.begin(), c.end()));
    check("double", c);
  }
}

TEST(VtkLegacy, AcceptsWindowsLineEndingsAndLowerCaseKeywords) {
  const fs::path dir = scratch_dir();
  std::string text;
  for (const char c : std::string(kTwoHexes)) text += c == '\n' ? std::string("\r\n") : std::string(1, c);
  write_text(dir / "crlf.vtk", text);
  expect_same_mesh(two_hexes(), io::read_mesh(dir / "crlf.vtk"));
  write_text(dir / "lower.vtk", replaced(replaced(kTwoHexes, "CELL_TYPES", "cell_types"), "POINTS", "points"));
  expect_same_mesh(two_hexes(), io::read_mesh(dir / "lower.vtk"));
}

TEST(VtkLegacy, ReadsBlockIdsUnderTheirUsualNames) {
  const fs::path dir = scratch_dir();
  for (const char* name : {"block", "BlockId", "CellEntityIds", "gmsh:physical", "MaterialIds"}) {
    const std::string text =
        std::string(kTwoHexes) + "CELL_DATA 2\nSCALARS " + name + " int 1\nLOOKUP_TABLE default\n3 4\n";
    write_text(dir / "blocks.vtk", text);
    EXPECT_EQ(io::read_mesh(dir / "blocks.vtk").blocks, (std::vector<Index>{3, 4})) << name;
  }
  // Other cell arrays are not blocks; a non-integer block id is an error.
  write_text(dir / "other.vtk",
             std::string(kTwoHexes) + "CELL_DATA 2\nSCALARS quality float\nLOOKUP_TABLE default\n3 4\n");
  EXPECT_FALSE(io::read_mesh(dir / "other.vtk").has_blocks());
  expect_text_error(dir, "half.vtk",
                    std::string(kTwoHexes) + "CELL_DATA 2\nSCALARS block float\nLOOKUP_TABLE default\n3 4.5\n",
                    {": line 27: ", "cell 1 has block 4.5, not a 32-bit integer"});
}

TEST(VtkLegacy, ReadsVoxelsInHexOrder) {
  const fs::path dir = scratch_dir();
  // The first cell as a voxel: corners in lexicographic order (x fastest).
  const std::string text =
      replaced(replaced(kTwoHexes, "8 0 1 4 3 6 7 10 9", "8 0 1 3 4 6 7 9 10"), "12\n12\n", "11\n12\n");
  write_text(dir / "voxel.vtk", text);
  expect_same_mesh(two_hexes(), io::read_mesh(dir / "voxel.vtk"));
}

TEST(VtkLegacy, NonHexCellsFailOrAreSkipped) {
  const fs::path dir = scratch_dir();
  const std::string text = replaced(replaced(kTwoHexes, "CELLS 2 18", "CELLS 4 30"), "CELL_TYPES 2\n12\n12\n",
                                    "4 0 1 3 6\n6 0 1 3 6 7 9\nCELL_TYPES 4\n12\n12\n10\n13\n");
  expect_text_error(dir, "mixed.vtk", text,
                    {": line 26: ", "2 of 4 cells are not hexahedra", "cell 2 (tetrahedron, VTK type 10)",
                     "cell 3 (wedge, VTK type 13)"});
  ReadOptions skip;
  skip.skip_non_hex = true;
  ReadReport report;
  const HexMesh m = io::read_mesh(dir / "mixed.vtk", skip, &report);
  EXPECT_EQ(report.skipped_cells, 2u);
  expect_same_mesh(two_hexes(), m);
  // Block ids of skipped cells are dropped with them.
  write_text(dir / "mixed_blocks.vtk", text + "CELL_DATA 4\nSCALARS block int\nLOOKUP_TABLE default\n1 2 3 4\n");
  EXPECT_EQ(io::read_mesh(dir / "mixed_blocks.vtk", skip).blocks, (std::vector<Index>{1, 2}));
}

TEST(VtkLegacy, MalformedAsciiFilesNameTheLineAndTheFault) {
  const fs::path dir = scratch_dir();
  const std::string good = kTwoHexes;
  expect_text_error(dir, "empty.vtk", "", {": line 1: ", "not a legacy VTK file"});
  expect_text_error(dir, "polydata.vtk", replaced(good, "UNSTRUCTURED_GRID", "POLYDATA"),
                    {": line 4: ", "dataset type 'POLYDATA' is not supported"});
  expect_text_error(dir, "mode.vtk", replaced(good, "ASCII", "TEXT"), {": line 3: ", "expected ASCII or BINARY"});
  expect_text_error(dir, "id.vtk", replaced(good, "8 1 2 5 4 7 8 11 10", "8 1 2 5 4 7 8 900 10"),
                    {": line 20: ", "cell 1 has vertex id 900 out of range [0, 11]"});
  expect_text_error(dir, "negative.vtk", replaced(good, "8 0 1 4 3", "8 0 -1 4 3"),
                    {": line 19: ", "cell 0 has vertex id -1 out of range [0, 11]"});
  expect_text_error(dir, "word.vtk", replaced(good, "1 1 0\n", "1 abc 0\n"),
                    {": line 10: ", "expected point coordinate (a finite number), found 'abc'"});
  expect_text_error(dir, "nan.vtk", replaced(good, "2 1 1\n", "2 nan 1\n"), {": line 17: ", "found 'nan'"});
  expect_text_error(dir, "inf.vtk", replaced(good, "2 1 1\n", "2 1 -inf\n"), {": line 17: ", "found '-inf'"});
  expect_text_error(dir, "keyword.vtk", good + "FOO 3\n", {": line 24: ", "unknown keyword 'FOO'"});
  expect_text_error(dir, "size.vtk", replaced(good, "CELLS 2 18", "CELLS 2 19"),
                    {": line 20: ", "CELLS size is 19 but its 2 cells hold 18 values"});
  expect_text_error(dir, "npts.vtk", replaced(good, "CELLS 2 18", "CELLS 2 17"),
                    {": line 20: ", "cell 1 declares 8 points"});
  expect_text_error(dir, "types.vtk", replaced(good, "CELL_TYPES 2", "CELL_TYPES 3"),
                    {": line 21: ", "CELL_TYPES has 3 entries for 2 cells"});
  expect_text_error(dir, "pointdata.vtk", good + "POINT_DATA 11\n",
                    {": line 24: ", "POINT_DATA has 11 values for 12 points"});
  expect_text_error(dir, "seven.vtk",
                    replaced(replaced(good, "CELLS 2 18", "CELLS 2 17"), "8 0 1 4 3 6 7 10 9", "7 0 1 4 3 6 7 10"),
                    {": line 22: ", "cell 0 is a hexahedron (VTK type 12) with 7 points instead of 8"});
  expect_text_error(dir, "type.vtk", replaced(good, "12\n12\n", "12\n99\n"),
                    {": line 23: ", "cell 1 has unknown VTK cell type 99"});
  ReadOptions skip;
  skip.skip_non_hex = true;
  expect_text_error(dir, "type_skip.vtk", replaced(good, "12\n12\n", "12\n-4\n"),
                    {": line 23: ", "unknown VTK cell type -4"}, skip);
  expect_text_error(dir, "datatype.vtk", replaced(good, "POINTS 12 float", "POINTS 12 real"),
                    {": line 5: ", "unknown data type 'real'"});
  expect_text_error(dir, "nocells.vtk", good.substr(0, good.find("CELLS")), {"no CELLS section"});
  expect_text_error(dir, "order.vtk", replaced(good, "POINTS 12 float", "CELLS 0 0\nPOINTS 12 float"),
                    {": line 5: ", "CELLS before POINTS"});
}

TEST(VtkLegacy, MalformedOffsetsAreRefused) {
  const fs::path dir = scratch_dir();
  const std::string good = every_section_file(false);
  expect_text_error(dir, "first.vtk", replaced(good, "0 8 16\n", "1 8 16\n"),
                    {"the first cell offset must be 0, found 1"});
  expect_text_error(dir, "down.vtk", replaced(good, "0 8 16\n", "0 9 8\n"),
                    {"cell offset 2 is 8, less than the previous offset 9"});
  expect_text_error(dir, "last.vtk", replaced(good, "0 8 16\n", "0 8 15\n"),
                    {"the last cell offset is 15 but CELLS declares 16 connectivity values"});
  expect_text_error(dir, "float.vtk", replaced(good, "OFFSETS vtktypeint32", "OFFSETS float"),
                    {"cell offset must have an integer type, not 'float'"});
  expect_text_error(dir, "noconn.vtk", replaced(good, "CONNECTIVITY", "CONNECTIONS"),
                    {"expected CONNECTIVITY, found 'CONNECTIONS'"});
}

TEST(VtkLegacy, MalformedBinaryFilesNameTheByteOffset) {
  const fs::path dir = scratch_dir();
  std::vector<double> c = coordinates(two_hexes());
  c[7] = std::numeric_limits<double>::quiet_NaN();  // point 2, y
  VtkBuilder b(true, "4.2");
  b.line("POINTS 12 double");
  const std::size_t data = b.size();
  b.values(c);
  expect_text_error(dir, "nan.vtk", b.str(),
                    {fmt::format(": byte {}: ", data + 7 * 8), "point 2 has a non-finite coordinate"});

  VtkBuilder ids(true, "4.2");
  ids.line("POINTS 12 double").values(coordinates(two_hexes())).line("CELLS 1 9");
  const std::size_t cells = ids.size();
  ids.values(std::vector<std::int32_t>{8, 0, 1, 2, 3, 4, 5, 6, -12});
  expect_text_error(dir, "id.vtk", ids.str(),
                    {fmt::format(": byte {}: ", cells + 8 * 4), "vertex id -12 out of range"});

  VtkBuilder junk(true, "4.2");
  junk.line("POINTS 12 double").values(coordinates(two_hexes()));
  const std::size_t after = junk.size();
  expect_text_error(dir, "junk.vtk", junk.str() + "\x01\x02garbage\n",
                    {fmt::format(": byte {}: ", after), "unknown keyword '\\x01\\x02garbage'"});
}

TEST(VtkLegacy, HugeDeclaredCountsAreRefusedQuickly) {
  const fs::path dir = scratch_dir();
  const auto start = std::chrono::steady_clock::now();
  const std::string head = "# vtk DataFile Version 4.2\nhuge\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  const std::string bin = "# vtk DataFile Version 4.2\nhuge\nBINARY\nDATASET UNSTRUCTURED_GRID\n";
  expect_text_error(dir, "a.vtk", head + "POINTS 999999999999 double\n0 0 0\n", {": line 5: ", "exceeds the limit"});
  expect_text_error(dir, "b.vtk", head + "POINTS 2000000000 double\n0 0 0\n",
                    {": line 5: ", "declares 6000000000 values"});
  expect_text_error(dir, "c.vtk", bin + "POINTS 2000000000 double\n\x3f\xf0",
                    {": byte ", "declares 6000000000 values"});
  expect_text_error(dir, "d.vtk", head + "POINTS 1 double\n0 0 0\nCELLS 1 999999999999999\n8 0 0 0 0 0 0 0 0\n",
                    {": line 7: ", "CELLS declares 999999999999999 values"});
  expect_text_error(
      dir, "e.vtk",
      head +
          "POINTS 1 double\n0 0 0\nCELLS 2 9223372036854775807\nOFFSETS vtktypeint64\n0 9223372036854775807\n"
          "CONNECTIVITY vtktypeint64\n0\n",
      {"CONNECTIVITY declares 9223372036854775807 values"});
  expect_text_error(dir, "f.vtk", head + "POINTS 1 double\n0 0 0\nFIELD f 1\nx 100000000 100000000 double\n1\n",
                    {"x declares 10000000000000000 values"});
  expect_text_error(dir, "g.vtk", head + "POINTS 1 double\n0 0 0\nCELLS 99999999999 99999999999\n",
                    {": line 7: ", "99999999999 cells exceed the limit"});
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
}

TEST(VtkLegacy, EveryTruncationOfAGeneratedFileFails) {
  const fs::path dir = scratch_dir();
  for (const bool binary : {true, false})
    for (const bool data : {false, true}) {
      SCOPED_TRACE(fmt::format("binary {} data {}", binary, data));
      const HexMesh m = awkward_mesh(data, data);
      WriteOptions w;
      w.binary = binary;
      io::write_mesh(dir / "full.vtk", m, w);
      const std::string full = io::read_file(dir / "full.vtk");
      // Only the end, or (binary) a cut just before an optional CELL_DATA / POINT_DATA section
      // or after its first line (a data section may hold no arrays), leaves a valid file; an
      // ASCII cut inside the last number of an array may, too.
      const std::size_t cell_data = full.find("CELL_DATA"), point_data = full.find("POINT_DATA");
      const auto around = [&](std::size_t n, std::size_t keyword) {
        return n + 1 >= keyword && n <= full.find('\n', keyword) + 1 && n != full.find(' ', keyword) + 1;
      };
      const auto may_succeed = [&](std::size_t n) {
        if (n + 1 >= full.size()) return true;
        if (data && !binary) return n + 1 >= cell_data;
        return data && (around(n, cell_data) || around(n, point_data));
      };
      sweep_prefixes(dir, "cut.vtk", full, all_lengths(full.size()), m, may_succeed);
    }
}

TEST(VtkLegacy, TruncatedSharedFilesFailCleanly) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  for (const char* name : {"hexmeshes/notch_stress_fixed.vtk", "hexmeshes/rockarm.vtk"}) {
    SCOPED_TRACE(name);
    const std::string full = io::read_file(shared_data(name));
    ReadOptions skip;
    skip.skip_non_hex = true;
    const HexMesh whole = io::read_mesh(shared_data(name), skip);
    // Whatever reads without error must at least hold all the cells.
    const std::size_t types = full.find("CELL_TYPES");
    sweep_prefixes(dir, "cut.vtk", full, spread_lengths(full.size(), 300), whole,
                   [&](std::size_t n) { return n > types; });
  }
}

TEST(VtkLegacy, FailedWritesLeaveNothingBehind) {
  const fs::path dir = scratch_dir();
  const HexMesh m = awkward_mesh(true, true);
  for (const bool binary : {true, false}) {
    WriteOptions w;
    w.binary = binary;
    EXPECT_THROW(io::write_mesh(dir / "missing" / "m.vtk", m, w), Error);
    EXPECT_FALSE(fs::exists(dir / "missing"));
    fs::create_directory(dir / "taken.vtk");  // renaming onto a folder fails
    EXPECT_THROW(io::write_mesh(dir / "taken.vtk", m, w), Error);
    EXPECT_TRUE(fs::is_directory(dir / "taken.vtk"));
    HexMesh bad = m;
    bad.hexes[3][5] = 999;
    try {
      io::write_mesh(dir / "bad.vtk", bad, w);
      ADD_FAILURE() << "an out-of-range vertex id was written";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("hex 3 has vertex id 999 out of range"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "bad.vtk"));
    EXPECT_TRUE(hidden_files(dir).empty());
  }
}

}  // namespace
}  // namespace isohex::test
