// MEDIT / GMF reader and writer: the ECR files, exact round trips, the syntax variants a
// reader meets (case, comments, line breaks, skipped sections), malformed input and
// truncation at every offset.

#include "io_legacy_support.hpp"

#include <chrono>

namespace isohex::test {
namespace {

using io::ReadOptions;
using io::ReadReport;
using io::WriteOptions;

// Two hexes sharing a face; the hexahedra are on lines 23 and 24, End on line 25.
constexpr const char* kTwoHexes = R"(MeshVersionFormatted 1
Dimension 3
Vertices
12
0 0 0 0
1 0 0 0
2 0 0 0
0 1 0 0
1 1 0 0
2 1 0 0
0 0 1 0
1 0 1 0
2 0 1 0
0 1 1 0
1 1 1 0
2 1 1 0
Quadrilaterals
2
1 2 5 4 3
2 3 6 5 3
Hexahedra
2
1 2 5 4 7 8 11 10 0
2 3 6 5 8 9 12 11 0
End
)";

TEST(Medit, EcrFilesLoadWithTheirCounts) {
  ISOHEX_REQUIRE_SHARED_DATA();
  struct Counts {
    const char* name;
    Index vertices, hexes;
  };
  const Counts files[] = {{"block", 3180, 2520},
                          {"bust", 6314, 5258},
                          {"hanger_stresstest", 6633, 4539},
                          {"impeller_stresstest", 15248, 11174},
                          {"dragon", 18147, 14009},
                          {"armadillo", 34726, 29935}};
  for (const Counts& c : files)
    for (const char* suffix : {"_in", "_out"}) {
      const std::string name = std::string("hexmeshes/ecr2015_") + c.name + suffix + ".mesh";
      ReadReport report;
      const HexMesh m = io::read_mesh(shared_data(name), {}, &report);
      EXPECT_EQ(report.format, "MEDIT version 1") << name;
      EXPECT_EQ(m.num_vertices(), c.vertices) << name;
      EXPECT_EQ(m.num_hexes(), c.hexes) << name;
      // Every hexahedron has reference 1; vertex references are -1, so nothing is fixed.
      ASSERT_TRUE(m.has_blocks()) << name;
      EXPECT_EQ(std::count(m.blocks.begin(), m.blocks.end(), 1), c.hexes) << name;
      EXPECT_FALSE(m.has_fixed()) << name;
    }
  const HexMesh block = io::read_mesh(shared_data("hexmeshes/ecr2015_block_in.mesh"));
  EXPECT_EQ(block.points[0], Vec3(0.309011, 0.327493, 0.226576));  // line 5
  EXPECT_EQ(block.hexes[1], (Hex{3, 2, 8, 9, 7, 6, 10, 11}));      // "4 3 9 10 8 7 11 12 1"
}

TEST(Medit, RoundTripsAwkwardCoordinatesExactly) {
  const fs::path dir = scratch_dir();
  for (const bool blocks : {false, true})
    for (const bool fixed : {false, true}) {
      SCOPED_TRACE(fmt::format("blocks {} fixed {}", blocks, fixed));
      const HexMesh m = awkward_mesh(blocks, fixed);
      io::write_mesh(dir / "m.mesh", m);
      ReadReport report;
      const HexMesh back = io::read_mesh(dir / "m.mesh", {}, &report);
      EXPECT_EQ(report.format, "MEDIT version 2");
      expect_same_mesh(m, back);
    }
}

TEST(Medit, RoundTripsSharedFiles) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  for (const char* name : {"hexmeshes/ecr2015_block_in.mesh", "hexmeshes/ecr2015_dragon_out.mesh",
                           "hexmeshes/mesquite/pave2.e.vtk", "hexmeshes/automesh_letter_f_3d.inp"}) {
    SCOPED_TRACE(name);
    const HexMesh m = io::read_mesh(shared_data(name));
    io::write_mesh(dir / "copy.mesh", m);
    expect_same_mesh(m, io::read_mesh(dir / "copy.mesh"));
  }
}

TEST(Medit, ReadsTheSyntaxVariantsOfOtherWriters) {
  const fs::path dir = scratch_dir();
  const HexMesh expected = grid_mesh(2, 1, 1);
  // Keywords in any case, values on following lines, comments, sections that are skipped.
  std::string text = replaced(kTwoHexes, "MeshVersionFormatted 1\nDimension 3\n",
                              "# made by hand\nmeshversionformatted\n2\n\nDIMENSION\n  3 # three\nCorners 2 1 3\n");
  text = replaced(text, "Hexahedra\n",
                  "Edges 1\n1 2 7\nTriangles\n1\n1 2 3 4\nRidges 1 1\nRequiredEdges 1 1\nNormals 1 0 0 1\n"
                  "NormalAtVertices 1 1 1\nNormalAtTriangleVertices 1 1 1 1\nNormalAtQuadrilateralVertices 1 1 1 1\n"
                  "Tangents 1 1 0 0\nTangentAtEdgeVertices 1 1 1 1\nSolAtVertices 2 2 1 2\n1.5 1 2 3\n2.5 4 5 6\n"
                  "Iterations 3\nTime 0.5\nhExAhEdRa\n");
  write_text(dir / "variants.mesh", text);
  ReadReport report;
  expect_same_mesh(expected, io::read_mesh(dir / "variants.mesh", {}, &report));
  EXPECT_EQ(report.format, "MEDIT version 2");
}

TEST(Medit, VertexFlagsAndRequiredVerticesMarkFixedVertices) {
  const fs::path dir = scratch_dir();
  // References 0/1 are fixed flags (the writer's convention).
  write_text(dir / "flags.mesh", replaced(replaced(kTwoHexes, "1 0 0 0\n", "1 0 0 1\n"), "2 1 1 0\n", "2 1 1 1\n"));
  HexMesh m = io::read_mesh(dir / "flags.mesh");
  ASSERT_TRUE(m.has_fixed());
  EXPECT_EQ(m.fixed, (std::vector<std::uint8_t>{0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1}));
  // Other references are labels, not flags.
  write_text(dir / "labels.mesh", replaced(replaced(kTwoHexes, "1 0 0 0\n", "1 0 0 1\n"), "2 1 1 0\n", "2 1 1 2\n"));
  EXPECT_FALSE(io::read_mesh(dir / "labels.mesh").has_fixed());
  // RequiredVertices always are.
  write_text(dir / "required.mesh", replaced(kTwoHexes, "End", "RequiredVertices\n2\n3 12\nEnd"));
  m = io::read_mesh(dir / "required.mesh");
  EXPECT_EQ(m.fixed, (std::vector<std::uint8_t>{0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 1}));
}

TEST(Medit, NonHexCellsFailOrAreSkipped) {
  const fs::path dir = scratch_dir();
  const std::string text = replaced(kTwoHexes, "End", "Tetrahedra\n1\n1 2 4 7 5\nPrisms 1\n1 2 4 7 8 10 0\nEnd");
  expect_text_error(dir, "tets.mesh", text, {": line 25: ", "1 Tetrahedra are not hexahedra", "skip_non_hex"});
  ReadOptions skip;
  skip.skip_non_hex = true;
  ReadReport report;
  const HexMesh m = io::read_mesh(dir / "tets.mesh", skip, &report);
  EXPECT_EQ(report.skipped_cells, 2u);
  expect_same_mesh(grid_mesh(2, 1, 1), m);
  expect_text_error(dir, "pyramids.mesh",
                    replaced(kTwoHexes, "End", "Pyramids 3\n1 2 5 4 7 0\n1 2 5 4 7 0\n1 2 5 4 7 0\nEnd"),
                    {": line 25: ", "3 Pyramids are not hexahedra"});
}

TEST(Medit, MalformedFilesNameTheLineAndTheFault) {
  const fs::path dir = scratch_dir();
  const std::string good = kTwoHexes;
  expect_text_error(dir, "keyword.mesh", replaced(good, "Quadrilaterals", "Quadrangles"),
                    {": line 17: ", "unknown keyword 'Quadrangles'"});
  expect_text_error(dir, "zero.mesh", replaced(good, "2 3 6 5 8 9 12 11 0", "2 3 6 5 8 9 0 11 0"),
                    {": line 24: ", "hexahedron 2 has vertex id 0 out of range [1, 12]"});
  expect_text_error(dir, "big.mesh", replaced(good, "1 2 5 4 7 8 11 10 0", "1 2 5 4 7 8 13 10 0"),
                    {": line 23: ", "hexahedron 1 has vertex id 13 out of range [1, 12]"});
  expect_text_error(dir, "negative.mesh", replaced(good, "1 2 5 4 7 8 11 10 0", "1 -2 5 4 7 8 11 10 0"),
                    {": line 23: ", "vertex id -2 out of range"});
  expect_text_error(dir, "word.mesh", replaced(good, "1 1 0 0\n", "1 one 0 0\n"),
                    {": line 9: ", "expected a vertex y coordinate (a finite number), found 'one'"});
  expect_text_error(dir, "nan.mesh", replaced(good, "1 1 0 0\n", "1 1 NaN 0\n"), {": line 9: ", "found 'NaN'"});
  expect_text_error(dir, "inf.mesh", replaced(good, "1 1 0 0\n", "inf 1 0 0\n"), {": line 9: ", "found 'inf'"});
  expect_text_error(dir, "count.mesh", replaced(good, "Quadrilaterals\n2", "Quadrilaterals\n3"),
                    {": line 21: ", "expected a value of Quadrilaterals (a number), found 'Hexahedra'"});
  expect_text_error(dir, "room.mesh", replaced(good, "Hexahedra\n2", "Hexahedra\n3"),
                    {": line 22: ", "3 Hexahedra declared, more than the 45 bytes left in the file can hold"});
  expect_text_error(dir, "short.mesh", replaced(good, "Vertices\n12", "Vertices\n13"),
                    {": line 17: ", "expected a vertex x coordinate (a finite number), found 'Quadrilaterals'"});
  expect_text_error(dir, "ref.mesh", replaced(good, "12 11 0\n", "12 11 1.5\n"), {": line 24: ", "found '1.5'"});
  expect_text_error(dir, "dim.mesh", replaced(good, "Dimension 3", "Dimension 2"), {": line 2: ", "only 3-D meshes"});
  expect_text_error(dir, "version.mesh", replaced(good, "MeshVersionFormatted 1", "MeshVersionFormatted 7"),
                    {": line 1: ", "MeshVersionFormatted 7"});
  expect_text_error(dir, "order.mesh",
                    replaced(replaced(good, "Hexahedra\n2\n1 2 5 4 7 8 11 10 0\n2 3 6 5 8 9 12 11 0\n", ""), "Vertices",
                             "Hexahedra 0\nVertices"),
                    {": line 3: ", "Hexahedra before Vertices"});
  expect_text_error(dir, "nodim.mesh", replaced(good, "Dimension 3\n", ""),
                    {": line 2: ", "Vertices before Dimension"});
  expect_text_error(dir, "noend.mesh", replaced(good, "End\n", ""), {": line 25: ", "no End keyword"});
  expect_text_error(dir, "empty.mesh", "", {": line 1: ", "no End keyword"});
}

TEST(Medit, HugeDeclaredCountsAreRefusedQuickly) {
  const fs::path dir = scratch_dir();
  const auto start = std::chrono::steady_clock::now();
  expect_text_error(dir, "a.mesh", "MeshVersionFormatted 2\nDimension 3\nVertices\n999999999999\n0 0 0 0\nEnd\n",
                    {": line 4: ", "999999999999 Vertices exceed the limit"});
  expect_text_error(dir, "b.mesh", "MeshVersionFormatted 2\nDimension 3\nVertices\n2000000000\n0 0 0 0\nEnd\n",
                    {": line 4: ", "2000000000 Vertices declared, more than the"});
  expect_text_error(dir, "c.mesh", "MeshVersionFormatted 2\nDimension 3\nVertices 0\nHexahedra -1\nEnd\n",
                    {": line 4: ", "negative number of Hexahedra"});
  expect_text_error(dir, "d.mesh", "MeshVersionFormatted 2\nDimension 3\nSolAtVertices 1000000000 1 4\nEnd\n",
                    {": line 3: ", "SolAtVertices"});
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
}

TEST(Medit, EveryTruncationOfAGeneratedFileFails) {
  const fs::path dir = scratch_dir();
  const HexMesh m = awkward_mesh(true, true);
  io::write_mesh(dir / "full.mesh", m);
  const std::string full = io::read_file(dir / "full.mesh");
  // End is required, so only dropping the final newline leaves a valid file.
  sweep_prefixes(dir, "cut.mesh", full, all_lengths(full.size()), m,
                 [&](std::size_t n) { return n + 1 >= full.size(); });
}

TEST(Medit, TruncatedSharedFileFailsCleanly) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  const std::string full = io::read_file(shared_data("hexmeshes/ecr2015_block_in.mesh"));
  const HexMesh whole = io::read_mesh(shared_data("hexmeshes/ecr2015_block_in.mesh"));
  sweep_prefixes(dir, "cut.mesh", full, spread_lengths(full.size(), 300), whole,
                 [&](std::size_t n) { return n + 2 >= full.size(); });  // the file ends "End\n\n"
}

TEST(Medit, FailedWritesLeaveNothingBehind) {
  const fs::path dir = scratch_dir();
  const HexMesh m = awkward_mesh(true, true);
  EXPECT_THROW(io::write_mesh(dir / "missing" / "m.mesh", m), Error);
  EXPECT_FALSE(fs::exists(dir / "missing"));
  fs::create_directory(dir / "taken.mesh");
  EXPECT_THROW(io::write_mesh(dir / "taken.mesh", m), Error);
  HexMesh bad = m;
  bad.points[4].y() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(io::write_mesh(dir / "bad.mesh", bad), Error);
  EXPECT_FALSE(fs::exists(dir / "bad.mesh"));
  bad = m;
  bad.blocks.pop_back();
  EXPECT_THROW(io::write_mesh(dir / "bad.mesh", bad), Error);
  EXPECT_FALSE(fs::exists(dir / "bad.mesh"));
  EXPECT_TRUE(hidden_files(dir).empty());
}

}  // namespace
}  // namespace isohex::test
