// Abaqus .inp reader and writer: automesh's files, exact round trips, arbitrary ids,
// continuation lines, element sets as blocks, the FIXED node set, malformed input and
// truncation; numbers in the 20 characters CalculiX reads.

#include "io_legacy_support.hpp"
#include "isohex/io/abaqus.hpp"

#include <cstdlib>
#include <random>

namespace isohex::test {
namespace {

using io::ReadOptions;
using io::ReadReport;

// grid_mesh(2, 1, 1) with node id 1000 - 7 v for vertex v, listed in vertex order; element
// 20 (hex 1, continued on line 19) comes before element 10 (hex 0, line 22).
constexpr const char* kTwoHexes = R"(** written by hand
*Heading
 two hexes, with a comma
*Node, nset=all
1000, 0, 0, 0
993, 1, 0, 0
986, 2, 0, 0
979, 0, 1, 0
972, 1, 1, 0
965, 2, 1, 0
958, 0, 0, 1
951, 1, 0, 1
944, 2, 0, 1
937, 0, 1, 1
930, 1, 1, 1
923, 2, 1, 1
*Element, type=C3D8R, elset=EB2
20, 993, 986, 965, 972,
 951, 944, 923, 930
*ELEMENT, TYPE=C3D8I,
 ELSET=eb5
10, 1000, 993, 972, 979, 958, 951, 930, 937
*Solid Section, elset=EB2, material=steel
,
*Material, name=steel
*Elastic
 2.0D+11, 0.3
)";

HexMesh two_hexes(std::vector<Index> blocks = {5, 2}) {
  HexMesh m = grid_mesh(2, 1, 1);
  m.blocks = std::move(blocks);
  return m;
}

/// awkward_mesh with -DBL_MAX, which no 20-character field holds exactly, as -1e308.
HexMesh awkward_mesh_in_20_characters(bool with_blocks, bool with_fixed) {
  HexMesh m = awkward_mesh(with_blocks, with_fixed);
  for (Vec3& p : m.points)
    for (int c = 0; c < 3; ++c)
      if (p[c] == -std::numeric_limits<double>::max()) p[c] = -1e308;
  return m;
}

/// Reals that are hard to spell in 20 characters: negative, tiny, huge, subnormal, beside
/// the largest double, at the ends of %g's fixed range; random bit patterns (every sign and
/// exponent); random coordinates of an ordinary mesh (1e-4 to 10 in size).
std::vector<double> hard_reals() {
  const double big = std::numeric_limits<double>::max(), tiny = std::numeric_limits<double>::denorm_min();
  std::vector<double> v = {-0.018695458531368891, -1.2345678901234567e-300, 1.2345678901234567e-300, -big, big,
                           std::nextafter(big, 0.0), -std::nextafter(big, 0.0), -std::numeric_limits<double>::min(),
                           tiny, -3 * tiny, -1.2345678901234567e-310, -1.2345678901234567e17, 1.2345678901234567e17,
                           -1.2345678901234567e16, 1.2345678901234567e19, -1.2345678901234567e20,
                           -9.8765432109876543e99, -9.8765432109876543e100,
                           -0.0012345678901234567, -0.00012345678901234567, -1.2345678901234567e-5,
                           -9.9999999999999995e-5, -0.099999999999999992, -1.0 / 3.0, -2.0 / 3.0 * 1e-3, -0.0, 0.0,
                           0.1, -M_PI * 1e-7};
  std::mt19937_64 rng(15);
  while (v.size() < 20000) {
    const double x = std::bit_cast<double>(rng());
    if (std::isfinite(x)) v.push_back(x);
  }
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> decade(-4, 1);
  for (int i = 0; i < 20000; ++i) v.push_back(unit(rng) * std::pow(10.0, decade(rng)));
  return v;
}

/// The decimal exponent of x's 17-digit rounding (log10 can be one off next to a power of 10).
int decimal_exponent(double x) {
  const std::string s = fmt::format("{:.16e}", x);
  return std::stoi(s.substr(s.find('e') + 1));
}

/// The significant digits a field of 20 characters holds for x, worked out from the lengths
/// of its spellings: fixed without the 0 before the point (".0012..."), or with an exponent
/// as short as it goes ("1.2e-5", "1.2e17"); at most 17.
int digits_that_fit(double x) {
  if (x == 0) return 17;
  const int sign = std::signbit(x) ? 1 : 0, e = decimal_exponent(x);
  const int e_digits = static_cast<int>(std::to_string(std::abs(e)).size()) + (e < 0 ? 1 : 0);
  for (int p = 17;; --p) {
    const int exponent_form = sign + p + (p > 1 ? 1 : 0) + 1 + e_digits;
    const int fixed_form = e < 0 ? sign + 1 + (-e - 1) + p : e < p ? sign + p + 1 : 1000;
    if (std::min(exponent_form, fixed_form) <= static_cast<int>(io::kAbaqusFieldWidth)) return p;
  }
}

/// What a field written for x must read back as: x itself when its %.17g, its shortest exact
/// spelling or its integer digits fit 20 characters; otherwise x to within half a unit in the
/// digits_that_fit-th digit (and the error of reading that decimal into a double), never
/// infinite.
void expect_field_holds(double x, double back, std::string_view field) {
  SCOPED_TRACE(fmt::format("{:.17g} written as '{}'", x, field));
  const std::size_t width = io::kAbaqusFieldWidth;
  EXPECT_LE(field.size(), width);
  EXPECT_TRUE(std::isfinite(back));
  if (fmt::format("{:.17g}", x).size() <= width || fmt::format("{}", x).size() <= width ||
      (std::abs(x) >= 1e16 && fmt::format("{:.0f}", x).size() <= width)) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(back), std::bit_cast<std::uint64_t>(x));
    return;
  }
  int p = digits_that_fit(x);
  EXPECT_GE(p, 13);
  if (std::abs(x) > 1.797693134862315e308) --p;  // its rounding would pass the largest double
  // long double: half a unit in the 13th digit of a subnormal is below the smallest double.
  const long double bound = 0.5L * std::pow(10.0L, decimal_exponent(x) - p + 1) * (1 + 1e-12L) +
                            std::abs(x) * 0x1p-52L + std::numeric_limits<double>::denorm_min();
  EXPECT_LE(static_cast<long double>(std::abs(back - x)), bound);
}

TEST(Abaqus, AutomeshFilesLoad) {
  ISOHEX_REQUIRE_SHARED_DATA();
  ReadReport report;
  const HexMesh f = io::read_mesh(shared_data("hexmeshes/automesh_letter_f_3d.inp"), {}, &report);
  EXPECT_EQ(report.format, "Abaqus input");
  EXPECT_EQ(f.num_vertices(), 102);
  EXPECT_EQ(f.num_hexes(), 39);
  EXPECT_EQ(f.hexes[0], (Hex{0, 1, 6, 5, 30, 31, 36, 35}));  // "1, 1, 2, 7, 6, 31, 32, 37, 36"
  EXPECT_EQ(f.points[2], Vec3(2, 0, 0));
  ASSERT_TRUE(f.has_blocks());  // ELSET=EB1
  EXPECT_EQ(std::count(f.blocks.begin(), f.blocks.end(), 1), 39);
  EXPECT_FALSE(f.has_fixed());
  for (const char* name : {"oracles/automesh_single_valence_03.inp", "oracles/automesh_single_valence_04_noise2.inp"}) {
    const HexMesh s = io::read_mesh(shared_data(name));
    EXPECT_EQ(s.num_vertices(), 8) << name;
    ASSERT_EQ(s.num_hexes(), 1) << name;
    EXPECT_EQ(s.hexes[0], (Hex{0, 1, 3, 2, 4, 5, 7, 6})) << name;  // "1, 1,2,4,3,5,6,8,7"
  }
  EXPECT_EQ(io::read_mesh(shared_data("oracles/automesh_single_valence_03.inp")).points[2], Vec3(-0.5, 0.866025, 0));
}

TEST(Abaqus, ReadsIdsContinuationsAndSetsOfOtherWriters) {
  const fs::path dir = scratch_dir();
  write_text(dir / "two.inp", kTwoHexes);
  expect_same_mesh(two_hexes(), io::read_mesh(dir / "two.inp"));
  // Set names that are not all EB<n> are numbered by first appearance; no set is block 0.
  write_text(dir / "named.inp",
             replaced(replaced(kTwoHexes, "elset=EB2", "elset=Part-1"), " ELSET=eb5", " ELSET=\"part 2\""));
  expect_same_mesh(two_hexes({2, 1}), io::read_mesh(dir / "named.inp"));
  write_text(dir / "noset.inp", replaced(replaced(kTwoHexes, "elset=EB2", "elset=Part-1"), ",\n ELSET=eb5", ""));
  expect_same_mesh(two_hexes({0, 1}), io::read_mesh(dir / "noset.inp"));
  // Ids far apart go through the hash map.
  std::string sparse = kTwoHexes;
  for (const std::string id : {"993", "1000", "20"}) {
    const std::string to = "77777777777" + id;
    for (auto at = sparse.find(id); at != std::string::npos; at = sparse.find(id, at + to.size()))
      sparse.replace(at, id.size(), to);
  }
  write_text(dir / "sparse.inp", sparse);
  expect_same_mesh(two_hexes(), io::read_mesh(dir / "sparse.inp"));
}

TEST(Abaqus, FixedNodeSetMarksFixedVertices) {
  const fs::path dir = scratch_dir();
  write_text(dir / "list.inp",
             std::string(kTwoHexes) + "*Nset, nset=Fixed\n 986, 923,\n1000\n*NSET, NSET=OTHER\n993\n");
  HexMesh expected = two_hexes();
  expected.fixed = {1, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 1};
  expect_same_mesh(expected, io::read_mesh(dir / "list.inp"));
  write_text(dir / "generate.inp", std::string(kTwoHexes) + "*NSET, NSET=FIXED, GENERATE\n 923, 951, 14\n");
  expected.fixed = {0, 0, 0, 0, 0, 0, 0, 1, 0, 1, 0, 1};  // 923, 937, 951
  expect_same_mesh(expected, io::read_mesh(dir / "generate.inp"));
}

TEST(Abaqus, RoundTripsAwkwardCoordinatesExactly) {
  const fs::path dir = scratch_dir();
  for (const bool blocks : {false, true})
    for (const bool fixed : {false, true}) {
      SCOPED_TRACE(fmt::format("blocks {} fixed {}", blocks, fixed));
      const HexMesh m = awkward_mesh_in_20_characters(blocks, fixed);
      io::write_mesh(dir / "m.inp", m);
      expect_same_mesh(m, io::read_mesh(dir / "m.inp"));
    }
  // Blocks are grouped under one *ELEMENT each, set lines hold at most 16 ids.
  HexMesh big = grid_mesh(6, 5, 4);
  big.fixed.assign(big.points.size(), 1);
  big.blocks.resize(big.hexes.size());
  for (std::size_t h = 0; h < big.blocks.size(); ++h) big.blocks[h] = static_cast<Index>(h % 3);
  io::write_mesh(dir / "big.inp", big);
  expect_same_mesh(big, io::read_mesh(dir / "big.inp"));
  const std::string text = io::read_file(dir / "big.inp");
  EXPECT_NE(text.find("*ELEMENT, TYPE=C3D8, ELSET=EB2\n"), std::string::npos);
  std::size_t elements = 0, set_lines = 0;
  bool in_set = false;
  for (std::size_t at = 0, end; at < text.size(); at = end + 1) {
    end = text.find('\n', at);
    const std::string line = text.substr(at, end - at);
    elements += line.starts_with("*ELEMENT");
    if (in_set) {
      ++set_lines;
      EXPECT_LE(std::count(line.begin(), line.end(), ','), 15) << line;
    }
    in_set = in_set || line == "*NSET, NSET=FIXED";
  }
  EXPECT_EQ(elements, 3u);
  EXPECT_EQ(set_lines, (big.points.size() + 15) / 16);
}

TEST(Abaqus, RealsFitTwentyCharactersWithTheMostDigits) {
  for (const double x : hard_reals()) {
    const std::string field = io::abaqus_real(x);
    expect_field_holds(x, std::strtod(field.c_str(), nullptr), field);
    if (::testing::Test::HasFailure()) return;
  }
  // The most digits that fit, worked out by hand: 17 without the 0 before the point, fewer
  // with a short exponent; the largest double's 15 digits would round past it.
  const std::pair<double, const char*> spelled[] = {
      {-0.018695458531368891, "-.018695458531368891"},  // CalculiX truncated %.17g's 21 characters
      {0.33333333333333331, "0.33333333333333331"},     // %.17g where it fits
      {-0.0012345678901234567, "-.001234567890123457"},
      {-1.2345678901234567e-5, "-1.23456789012346e-5"},
      {-1.2345678901234567e-300, "-1.234567890123e-300"},
      {1.2345678901234567e-300, "1.2345678901235e-300"},
      {-1.2345678901234567e17, "-123456789012345664"},  // the double's exact integer digits
      {-1.2345678901234567e20, "-1.23456789012346e20"},
      {1.2345678901234567e20, "1.234567890123457e20"},
      {std::numeric_limits<double>::max(), "1.7976931348623e+308"},
      {-std::numeric_limits<double>::max(), "-1.7976931348623e308"},
      {1e-300, "1e-300"},
      {-0.0, "-0"}};
  for (const auto& [x, text] : spelled) EXPECT_EQ(io::abaqus_real(x), text) << fmt::format("{:.17g}", x);
}

TEST(Abaqus, EveryFieldOfAWrittenFileFitsCalculiX) {
  const fs::path dir = scratch_dir();
  const std::vector<double> reals = hard_reals();
  HexMesh m = grid_mesh(6, 5, 4);
  m.blocks.assign(m.hexes.size(), -2147483647);  // the longest ELSET name
  m.fixed.assign(m.points.size(), 1);
  for (std::size_t v = 0; v < m.points.size(); ++v)
    for (int c = 0; c < 3; ++c) m.points[v][c] = reals[(3 * v + static_cast<std::size_t>(c)) * 97 % reals.size()];
  for (std::size_t k = 0; k < 27; ++k) m.points[k / 3][static_cast<int>(k % 3)] = reals[k];  // the chosen ones
  io::write_mesh(dir / "m.inp", m);
  const std::string text = io::read_file(dir / "m.inp");
  std::size_t node_lines = 0;
  bool in_nodes = false;
  for (std::size_t at = 0, end; at < text.size(); at = end + 1) {
    end = text.find('\n', at);
    const std::string line = text.substr(at, end - at);
    EXPECT_LE(line.size(), 256u) << line;  // Abaqus' longest line
    if (line.starts_with("*")) {
      in_nodes = line.starts_with("*NODE");
      continue;
    }
    std::vector<std::string_view> fields;
    for (std::string_view rest = line;;) {
      const auto comma = rest.find(',');
      std::string_view f = rest.substr(0, comma);
      while (f.starts_with(' ')) f.remove_prefix(1);
      fields.push_back(f);
      if (comma == std::string_view::npos) break;
      rest.remove_prefix(comma + 1);
    }
    EXPECT_LE(fields.size(), 16u) << line;  // CalculiX splits a line into 16 fields at most
    for (const std::string_view f : fields) EXPECT_LE(f.size(), io::kAbaqusFieldWidth) << line;
    if (!in_nodes) continue;
    ASSERT_EQ(fields.size(), 4u) << line;
    const std::size_t v = node_lines++;
    EXPECT_EQ(fields[0], std::to_string(v + 1));
    for (std::size_t c = 0; c < 3; ++c) {
      const std::string field(fields[c + 1]);
      expect_field_holds(m.points[v][static_cast<int>(c)], std::strtod(field.c_str(), nullptr), field);
    }
  }
  EXPECT_EQ(node_lines, m.points.size());
  // isohex reads back what the fields say.
  const HexMesh back = io::read_mesh(dir / "m.inp");
  ASSERT_EQ(back.points.size(), m.points.size());
  for (std::size_t v = 0; v < m.points.size(); ++v)
    for (int c = 0; c < 3; ++c) {
      const std::string field = io::abaqus_real(m.points[v][c]);
      EXPECT_EQ(back.points[v][c], std::strtod(field.c_str(), nullptr)) << field;
    }
  HexMesh same = back;
  same.points = m.points;
  expect_same_mesh(m, same);
}

TEST(Abaqus, RoundTripsSharedFiles) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const fs::path dir = scratch_dir();
  for (const char* name : {"hexmeshes/automesh_letter_f_3d.inp", "hexmeshes/rockarm.vtk",
                           "hexmeshes/mesquite/hex_5_tangled.vtk", "hexmeshes/ecr2015_bust_out.mesh"}) {
    SCOPED_TRACE(name);
    const HexMesh m = io::read_mesh(shared_data(name));
    io::write_mesh(dir / "copy.inp", m);
    expect_same_mesh(m, io::read_mesh(dir / "copy.inp"));
  }
}

TEST(Abaqus, NonHexElementsFailOrAreSkipped) {
  const fs::path dir = scratch_dir();
  const std::string text = std::string(kTwoHexes) +
                           "*ELEMENT, TYPE=C3D4, ELSET=tets\n31, 1000, 993, 979, 958\n32, 993, 986, 972, 951\n"
                           "*ELEMENT, TYPE=C3D20R\n41, 1000, 993, 972, 979, 958, 951, 930, 937, 1000, 993,\n"
                           "972, 979, 958, 951, 930, 937, 1000, 993, 972, 979\n";
  expect_text_error(dir, "tets.inp", text,
                    {": line 29: ", "element 31 has type C3D4, not a hexahedron", "skip_non_hex"});
  ReadOptions skip;
  skip.skip_non_hex = true;
  ReadReport report;
  const HexMesh m = io::read_mesh(dir / "tets.inp", skip, &report);
  EXPECT_EQ(report.skipped_cells, 3u);
  expect_same_mesh(two_hexes(), m);
}

TEST(Abaqus, MalformedFilesNameTheLineAndTheFault) {
  const fs::path dir = scratch_dir();
  const std::string good = kTwoHexes;
  expect_text_error(dir, "unknown.inp", replaced(good, "1000, 993, 972, 979", "1000, 993, 900, 979"),
                    {": line 22: ", "element 10 names node 900, which is not defined"});
  expect_text_error(dir, "zero.inp", replaced(good, "1000, 993, 972, 979", "1000, 0, 972, 979"),
                    {": line 22: ", "element 10 names node 0"});
  expect_text_error(dir, "negative.inp", replaced(good, " 951, 944, 923, 930", " 951, 944, -923, 930"),
                    {": line 18: ", "element 20 names node -923"});
  expect_text_error(dir, "seven.inp", replaced(good, ", 930, 937\n", ", 930\n"),
                    {": line 22: ", "element 10 of type C3D8I has 7 node ids instead of 8"});
  expect_text_error(dir, "nine.inp", replaced(good, ", 930, 937\n", ", 930, 937, 923\n"),
                    {": line 22: ", "has 9 node ids instead of 8"});
  expect_text_error(dir, "word.inp", replaced(good, "979, 0, 1, 0", "979, 0, abc, 0"),
                    {": line 8: ", "expected a node y coordinate (a finite number), found 'abc'"});
  expect_text_error(dir, "nan.inp", replaced(good, "979, 0, 1, 0", "979, 0, 1, NaN"), {": line 8: ", "found 'NaN'"});
  expect_text_error(dir, "inf.inp", replaced(good, "979, 0, 1, 0", "979, -Inf, 1, 0"), {": line 8: ", "found '-Inf'"});
  expect_text_error(dir, "two_coords.inp", replaced(good, "979, 0, 1, 0", "979, 0, 1"),
                    {": line 8: ", "node 979 has 2 coordinates, 3 are needed"});
  expect_text_error(dir, "node_twice.inp", replaced(good, "979, 0, 1, 0", "993, 0, 1, 0"),
                    {": line 8: ", "node 993 is defined twice"});
  expect_text_error(dir, "node_zero.inp", replaced(good, "979, 0, 1, 0", "0, 0, 1, 0"),
                    {": line 8: ", "node id 0 is not positive"});
  expect_text_error(dir, "element_twice.inp", replaced(good, "\n10, 1000", "\n20, 1000"),
                    {": line 22: ", "element 20 is defined twice"});
  expect_text_error(dir, "element_id.inp", replaced(good, "\n10, 1000", "\nten, 1000"),
                    {": line 22: ", "expected an element id (an integer), found 'ten'"});
  expect_text_error(dir, "notype.inp", replaced(good, "*Element, type=C3D8R, elset=EB2", "*Element, elset=EB2"),
                    {": line 17: ", "*ELEMENT without TYPE="});
  expect_text_error(dir, "include.inp", replaced(good, "*Heading", "*INCLUDE, INPUT=nodes.inp"),
                    {": line 2: ", "*INCLUDE is not supported"});
  expect_text_error(dir, "fixed.inp", good + "*NSET, NSET=FIXED\n1000, 5\n",
                    {": line 29: ", "NSET FIXED names node 5"});
  expect_text_error(dir, "generate.inp",
                    good + "*NSET, NSET=FIXED, GENERATE\n-9000000000000000000, 9000000000000000000\n",
                    {": line 29: ", "is not a range of defined nodes"});
  expect_text_error(dir, "generate2.inp",
                    good + "*NSET, NSET=FIXED, GENERATE\n1, 9223372036854775807, 9223372036854775806\n",
                    {": line 29: ", "NSET FIXED names node 1,"});
}

TEST(Abaqus, TruncationNeverCrashes) {
  const fs::path dir = scratch_dir();
  const HexMesh m = awkward_mesh(true, true);
  io::write_mesh(dir / "full.inp", m);
  const std::string full = io::read_file(dir / "full.inp");
  // The format has no end marker: a cut between lines is a smaller valid mesh.
  sweep_prefixes(dir, "cut.inp", full, all_lengths(full.size()), m, [](std::size_t) { return true; });
  if (have_shared_data()) {
    const fs::path letter = shared_data("hexmeshes/automesh_letter_f_3d.inp");
    sweep_prefixes(dir, "cut.inp", io::read_file(letter), all_lengths(9231), io::read_mesh(letter),
                   [](std::size_t) { return true; });
  }
}

TEST(Abaqus, FailedWritesLeaveNothingBehind) {
  const fs::path dir = scratch_dir();
  const HexMesh m = awkward_mesh(true, true);
  EXPECT_THROW(io::write_mesh(dir / "missing" / "m.inp", m), Error);
  EXPECT_FALSE(fs::exists(dir / "missing"));
  fs::create_directory(dir / "taken.inp");
  EXPECT_THROW(io::write_mesh(dir / "taken.inp", m), Error);
  HexMesh bad = m;
  bad.fixed.push_back(1);
  EXPECT_THROW(io::write_mesh(dir / "bad.inp", bad), Error);
  EXPECT_FALSE(fs::exists(dir / "bad.inp"));
  EXPECT_TRUE(hidden_files(dir).empty());
}

}  // namespace
}  // namespace isohex::test
