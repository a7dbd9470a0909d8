// Solver formats: Exodus II (.exo/.e/.ex2), Gmsh 4.1 (.msh, ASCII and binary) and the sets
// the Abaqus writer adds. Exact round trips, the face numbering tables against each
// format's documented face lists, deterministic and atomic writes, and malformed input.
// tests/oracle/test_formats_consumers.py proves the files with VTK, gmsh and a deck parser.

#include "io_legacy_support.hpp"
#include "isohex/io/solver_sets.hpp"
#include "isohex/mesh/topology.hpp"

#include <set>

namespace isohex::test {
namespace {

/// `q` rotated to start at its smallest entry: equal iff same quad with the same orientation.
Quad canonical(Quad q) {
  std::rotate(q.begin(), std::min_element(q.begin(), q.end()), q.end());
  return q;
}

HexMesh read_back(const fs::path& file, const HexMesh& mesh, const io::WriteOptions& options = {}) {
  io::write_mesh(file, mesh, options);
  return io::read_mesh(file);
}

TEST(SolverFormats, ExodusSideTableMatchesTheExodusManual) {
  // Exodus II manual, HEX8 sides in 1-based local nodes, counter-clockwise seen from outside.
  const int sides[6][4] = {{1, 2, 6, 5}, {2, 3, 7, 6}, {3, 4, 8, 7}, {1, 5, 8, 4}, {1, 4, 3, 2}, {5, 6, 7, 8}};
  for (int f = 0; f < 6; ++f) {
    const int s = io::kExodusSideOfVtkFace[static_cast<std::size_t>(f)] - 1;
    Quad vtk_face, exodus_side;
    for (int k = 0; k < 4; ++k) {
      vtk_face[static_cast<std::size_t>(k)] = kHexFaces[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)];
      exodus_side[static_cast<std::size_t>(k)] = sides[s][k] - 1;
    }
    EXPECT_EQ(canonical(vtk_face), canonical(exodus_side)) << "VTK face " << f;
  }
}

TEST(SolverFormats, AbaqusFaceTableMatchesTheAbaqusManual) {
  // Abaqus C3D8 faces S1..S6 in 1-based local nodes, as the element library lists them
  // (counter-clockwise seen from inside, so reversed they are outward).
  const int faces[6][4] = {{1, 2, 3, 4}, {5, 8, 7, 6}, {1, 5, 6, 2}, {2, 6, 7, 3}, {3, 7, 8, 4}, {4, 8, 5, 1}};
  for (int f = 0; f < 6; ++f) {
    const int s = io::kAbaqusFaceOfVtkFace[static_cast<std::size_t>(f)] - 1;
    Quad vtk_face, abaqus_face;
    for (int k = 0; k < 4; ++k) {
      vtk_face[static_cast<std::size_t>(k)] = kHexFaces[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)];
      abaqus_face[static_cast<std::size_t>(3 - k)] = faces[s][k] - 1;
    }
    EXPECT_EQ(canonical(vtk_face), canonical(abaqus_face)) << "VTK face " << f;
  }
}

TEST(SolverFormats, BoundaryFacesAreTheBoundaryQuads) {
  const HexMesh m = awkward_mesh(true, false);
  std::set<Quad> from_faces, quads;
  for (const io::BoundaryFace& f : io::boundary_faces(m)) {
    Quad q;
    for (int k = 0; k < 4; ++k)
      q[static_cast<std::size_t>(k)] = m.hexes[static_cast<std::size_t>(f.hex)][static_cast<std::size_t>(
          kHexFaces[static_cast<std::size_t>(f.face)][static_cast<std::size_t>(k)])];
    from_faces.insert(canonical(q));
  }
  for (const Quad& q : boundary_quads(m)) quads.insert(canonical(q));
  EXPECT_EQ(from_faces, quads);
  EXPECT_EQ(quads.size(), 2u * (3 * 2 + 3 * 2 + 2 * 2));
  EXPECT_EQ(io::boundary_nodes(m).size(), 4u * 3u * 3u - 2u);  // all but the 2 inner vertices
}

TEST(SolverFormats, BlockTableKeepsPositiveIdsAndRenumbersOthers) {
  HexMesh m = grid_mesh(3, 1, 1);
  m.blocks = {9, 4, 9};
  io::BlockTable t = io::block_table(m);
  EXPECT_EQ(t.values, (std::vector<Index>{4, 9}));
  EXPECT_EQ(t.file_ids, (std::vector<Index>{4, 9}));
  EXPECT_EQ(t.of_hex, (std::vector<Index>{1, 0, 1}));
  m.blocks = {0, -3, 7};
  t = io::block_table(m);
  EXPECT_EQ(t.file_ids, (std::vector<Index>{1, 2, 3}));
  Index v = 0;
  EXPECT_TRUE(io::parse_block_name(io::block_name(-3), v));
  EXPECT_EQ(v, -3);
  EXPECT_FALSE(io::parse_block_name("block_+3", v));
  EXPECT_FALSE(io::parse_block_name("block_", v));
  EXPECT_FALSE(io::parse_block_name("Block_3", v));
}

struct Variant {
  const char* name;
  bool blocks, fixed;
};
constexpr Variant kVariants[] = {{"plain", false, false}, {"blocks", true, false}, {"all", true, true}};

TEST(SolverFormats, ExodusRoundTripsExactly) {
  const fs::path dir = scratch_dir();
  for (const Variant& v : kVariants)
    for (const char* ext : {".exo", ".e", ".ex2", ".EXO"}) {
      SCOPED_TRACE(std::string(v.name) + ext);
      const HexMesh m = awkward_mesh(v.blocks, v.fixed);
      io::ReadReport report;
      io::write_mesh(dir / (std::string(v.name) + ext), m);
      const HexMesh back = io::read_mesh(dir / (std::string(v.name) + ext), {}, &report);
      expect_same_mesh(m, back);
      EXPECT_EQ(back.has_blocks(), v.blocks);
      EXPECT_EQ(back.has_fixed(), v.fixed);
      EXPECT_NE(report.format.find("Exodus II"), std::string::npos) << report.format;
    }
  EXPECT_TRUE(hidden_files(dir).empty());
}

TEST(SolverFormats, GmshRoundTripsExactlyInBothEncodings) {
  const fs::path dir = scratch_dir();
  for (const bool binary : {false, true})
    for (const Variant& v : kVariants) {
      SCOPED_TRACE(std::string(v.name) + (binary ? " binary" : " ascii"));
      io::WriteOptions options;
      options.msh_binary = binary;
      const HexMesh m = awkward_mesh(v.blocks, v.fixed);
      io::ReadReport report;
      io::write_mesh(dir / "m.msh", m, options);
      HexMesh back = io::read_mesh(dir / "m.msh", {}, &report);
      EXPECT_FALSE(back.has_fixed());  // Gmsh has no place for them
      back.fixed = m.fixed;
      expect_same_mesh(m, back);
      EXPECT_EQ(report.format, binary ? "Gmsh 4.1 binary" : "Gmsh 4.1 ASCII");
    }
}

TEST(SolverFormats, AbaqusWritesSetsAndSurfaceAndStillReadsBack) {
  const fs::path dir = scratch_dir();
  HexMesh m = grid_mesh(2, 1, 1);
  m.blocks = {5, 2};
  io::write_mesh(dir / "m.inp", m);
  const std::string text = io::read_file(dir / "m.inp");
  EXPECT_NE(text.find("*ELEMENT, TYPE=C3D8, ELSET=EB2\n2, "), std::string::npos) << text;
  EXPECT_NE(text.find("*ELEMENT, TYPE=C3D8, ELSET=EB5\n1, "), std::string::npos) << text;
  EXPECT_NE(text.find("*ELSET, ELSET=ALLHEXES, GENERATE\n1, 2, 1\n"), std::string::npos) << text;
  // Every vertex of a 2x1x1 grid is on the boundary: 12 nodes, 16 on a line at most.
  EXPECT_NE(text.find("*NSET, NSET=BOUNDARY\n1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12\n"), std::string::npos) << text;
  const auto surface = text.find("*SURFACE, NAME=BOUNDARY, TYPE=ELEMENT\n");
  ASSERT_NE(surface, std::string::npos) << text;
  // Hex 0 = element 1: its -x face (VTK face 0) is S6, its bottom (VTK face 4) S1.
  EXPECT_NE(text.find("1, S6\n", surface), std::string::npos);
  EXPECT_NE(text.find("1, S1\n", surface), std::string::npos);
  EXPECT_EQ(text.find("1, S4\n", surface), std::string::npos);  // the shared +x face is inside
  EXPECT_EQ(std::count(text.begin() + static_cast<std::ptrdiff_t>(surface), text.end(), 'S'), 1 + 10);
  expect_same_mesh(m, io::read_mesh(dir / "m.inp"));
  HexMesh f = awkward_mesh(true, true);
  for (Vec3& p : f.points)  // no 20-character field, the most CalculiX reads, holds -DBL_MAX exactly
    for (int c = 0; c < 3; ++c)
      if (p[c] == -std::numeric_limits<double>::max()) p[c] = -1e308;
  expect_same_mesh(f, read_back(dir / "f.inp", f));
}

TEST(SolverFormats, MeditStillRoundTrips) {
  const fs::path dir = scratch_dir();
  const HexMesh m = awkward_mesh(true, true);
  expect_same_mesh(m, read_back(dir / "m.mesh", m));
}

TEST(SolverFormats, OutputIsDeterministic) {
  const fs::path dir = scratch_dir();
  const HexMesh m = awkward_mesh(true, true);
  for (const char* name : {"a.exo", "a.msh", "a.inp"}) {
    io::write_mesh(dir / name, m);
    const std::string first = io::read_file(dir / name);
    io::write_mesh(dir / name, m);
    EXPECT_EQ(first, io::read_file(dir / name)) << name;
  }
}

TEST(SolverFormats, FailedWritesLeaveNothing) {
  const fs::path dir = scratch_dir();
  const HexMesh m = awkward_mesh(true, false);
  for (const char* name : {"x.exo", "x.msh"}) {
    // A folder in the way: the rename fails, the temporary file must go.
    fs::create_directories(dir / name / "inside");
    try {
      io::write_mesh(dir / name, m);
      ADD_FAILURE() << name << " written over a folder";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find((dir / name).string()), std::string::npos) << e.what();
    }
    EXPECT_TRUE(hidden_files(dir).empty()) << name;
    EXPECT_THROW(io::write_mesh(dir / "missing" / name, m), Error);
  }
  HexMesh bad = m;
  bad.hexes[1][3] = 1000;
  EXPECT_THROW(io::write_mesh(dir / "bad.exo", bad), Error);
  EXPECT_FALSE(fs::exists(dir / "bad.exo"));
  EXPECT_TRUE(hidden_files(dir).empty());
}

TEST(SolverFormats, ExodusRejectsWhatItCannotRead) {
  const fs::path dir = scratch_dir();
  expect_read_error(dir / "none.exo", {"no such file"});
  expect_text_error(dir, "text.exo", "not netCDF at all\n", {"not a readable Exodus II file"});
  // Truncated files: the library must refuse them (or read less), never crash.
  io::write_mesh(dir / "whole.exo", awkward_mesh(true, true));
  const std::string whole = io::read_file(dir / "whole.exo");
  for (const std::size_t length : spread_lengths(whole.size(), 40)) {
    write_text(dir / "cut.exo", whole.substr(0, length));
    try {
      const HexMesh m = io::read_mesh(dir / "cut.exo");
      EXPECT_LE(m.hexes.size(), 12u) << length;
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind((dir / "cut.exo").string() + ": ", 0), 0u) << e.what();
    }
  }
}

constexpr const char* kTinyMsh = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$Comments
anything $Nodes
$EndComments
$PhysicalNames
1
3 7 "steel"
$EndPhysicalNames
$Entities
0 0 0 1
4 0 0 0 1 1 1 1 7 0
$EndEntities
$Nodes
1 8 1 80
3 4 0 8
80
20
30
40
50
60
70
10
0 1 1
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 0 0
$EndNodes
$Elements
2 2 1 9
3 4 5 1
9 10 20 30 40 80 60 70 50
2 1 3 1
1 10 20 30 40
$EndElements
)";

TEST(SolverFormats, GmshReaderFollowsTagsAndPhysicalGroups) {
  const fs::path dir = scratch_dir();
  write_text(dir / "tiny.msh", kTinyMsh);
  const HexMesh m = io::read_mesh(dir / "tiny.msh");
  ASSERT_EQ(m.num_vertices(), 8);
  EXPECT_EQ(m.points[0], Vec3(0, 0, 0));  // tag 10
  EXPECT_EQ(m.points[7], Vec3(0, 1, 1));  // tag 80
  ASSERT_EQ(m.num_hexes(), 1);
  EXPECT_EQ(m.hexes[0], (Hex{0, 1, 2, 3, 7, 5, 6, 4}));
  EXPECT_EQ(m.blocks, (std::vector<Index>{7}));  // "steel" is no block_ name: the physical tag
}

TEST(SolverFormats, GmshReaderErrorsNameThePlace) {
  const fs::path dir = scratch_dir();
  const std::string tiny = kTinyMsh;
  expect_text_error(dir, "v2.msh", replaced(tiny, "4.1 0 8", "2.2 0 8"), {"line 2", "version 2.2", "4.1"});
  expect_text_error(dir, "v4.msh", replaced(tiny, "4.1 0 8", "4 0 8"), {"line 2", "version 4 "});
  expect_text_error(dir, "nofmt.msh", "$Nodes\n$EndNodes\n", {"line 1", "$MeshFormat"});
  expect_text_error(dir, "noelem.msh", tiny.substr(0, tiny.find("$Elements")), {"line 35", "no $Elements"});
  expect_text_error(dir, "badnode.msh", replaced(tiny, "1 0 1\n", "1 zero 1\n"), {"line 31", "node coordinate"});
  expect_text_error(dir, "undef.msh", replaced(tiny, "9 10 20", "9 11 20"), {"line 38", "element 9", "node 11"});
  expect_text_error(dir, "count.msh", replaced(tiny, "1 8 1 80", "1 9 1 80"), {"nodes", "9"});
  expect_text_error(dir, "type.msh", replaced(tiny, "3 4 5 1", "3 4 99 1"), {"line 37", "element type 99"});
  expect_text_error(dir, "end.msh", replaced(tiny, "$EndComments", "$EndComment"), {"$EndComments"});
  expect_text_error(dir, "huge.msh", replaced(tiny, "1 8 1 80", "1 800000000000 1 80"), {"line 16", "more than"});
  const std::string tet = replaced(replaced(tiny, "3 4 5 1", "3 4 4 1"), "9 10 20 30 40 80 60 70 50", "9 10 20 30 80");
  expect_text_error(dir, "tet.msh", tet, {"line 37", "type 4", "skip_non_hex"});
  io::ReadOptions skip;
  skip.skip_non_hex = true;
  io::ReadReport report;
  write_text(dir / "tet.msh", tet);
  EXPECT_EQ(io::read_mesh(dir / "tet.msh", skip, &report).num_hexes(), 0);
  EXPECT_EQ(report.skipped_cells, 1u);
}

TEST(SolverFormats, GmshTruncationsFailCleanly) {
  const fs::path dir = scratch_dir();
  const HexMesh m = awkward_mesh(true, false);
  for (const bool binary : {false, true}) {
    io::WriteOptions options;
    options.msh_binary = binary;
    io::write_mesh(dir / "whole.msh", m, options);
    const std::string whole = io::read_file(dir / "whole.msh");
    // Only the last bytes may go: the final "$EndElements" line's newline.
    sweep_prefixes(dir, "cut.msh", whole, spread_lengths(whole.size(), binary ? 400 : 200), m,
                   [&](std::size_t length) { return length + 1 >= whole.size(); });
  }
}

}  // namespace
}  // namespace isohex::test
