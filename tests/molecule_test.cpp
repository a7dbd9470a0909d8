// Molecules: PDB/PQR reading (counts, columns, filters, errors) and the Gaussian density
// (formula, cut-off error, thread-count independence).
#include "isohex/error.hpp"
#include "isohex/volume/molecule.hpp"
#include "isohex/volume/volume_io.hpp"
#include "test_support.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

namespace isohex {
namespace {

// One fixed-column PDB record (columns as in the PDB format guide).
std::string pdb_line(std::string_view record, std::string_view name, std::string_view res, double x, double y,
                     double z, std::string_view element = "", char altloc = ' ', int resseq = 1, char chain = 'A') {
  return fmt::format("{:<6}{:>5} {:<4}{}{:>3} {}{:>4}    {:>8.3f}{:>8.3f}{:>8.3f}{:>6.2f}{:>6.2f}          {:>2}\n",
                     record, 1, name, altloc, res, chain, resseq, x, y, z, 1.0, 10.0, element);
}

std::string error_of(auto&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

struct Expected {
  const char* file;
  std::size_t atom, hetatm;
};

TEST(Molecule, SharedFilesHaveTheDocumentedRecordCounts) {
  ISOHEX_REQUIRE_SHARED_DATA();
  // SOURCES.md, section molecules/.
  for (const Expected& e : {Expected{"mache_1MAH.pqr", 8279, 0}, Expected{"fas2_1FSC.pqr", 906, 0},
                            Expected{"4EY4.pdb", 8373, 532}, Expected{"1ACJ.pdb", 4095, 97},
                            Expected{"1UBQ.pdb", 602, 58}, Expected{"2LYZ.pdb", 1001, 101}}) {
    SCOPED_TRACE(e.file);
    MoleculeReadOptions all;
    all.hetatm = all.water = true;
    const Molecule m = read_molecule(test::shared_data(std::string("molecules/") + e.file), all);
    EXPECT_EQ(m.report.atom_records, e.atom);
    EXPECT_EQ(m.report.hetatm_records, e.hetatm);
    EXPECT_EQ(m.atoms.size() + m.report.altloc_skipped + m.report.zero_radius_skipped, e.atom + e.hetatm);
    for (const Atom& a : m.atoms) ASSERT_GT(a.radius, 0.0) << "line " << a.line;
  }
}

TEST(Molecule, SharedFilesDetails) {
  ISOHEX_REQUIRE_SHARED_DATA();
  // mAChE: every record is an ATOM with its own radius in 1.0-2.0 Å and the documented bbox.
  const Molecule mache = read_molecule(test::shared_data("molecules/mache_1MAH.pqr"));
  ASSERT_EQ(mache.atoms.size(), 8279u);
  Vec3 lo = mache.atoms[0].center, hi = lo;
  for (const Atom& a : mache.atoms) {
    EXPECT_GE(a.radius, 1.0);
    EXPECT_LE(a.radius, 2.0);
    lo = lo.cwiseMin(a.center);
    hi = hi.cwiseMax(a.center);
  }
  EXPECT_NEAR(lo.x(), -38.9, 0.05);
  EXPECT_NEAR(hi.x(), 34.9, 0.05);
  EXPECT_NEAR(lo.z(), -31.9, 0.05);
  EXPECT_NEAR(hi.z(), 23.6, 0.05);
  EXPECT_EQ(mache.atoms[1].element, "H");  // HT1
  EXPECT_TRUE(mache.atoms[1].hydrogen);
  MoleculeReadOptions no_h;
  no_h.hydrogens = false;
  const Molecule heavy = read_molecule(test::shared_data("molecules/mache_1MAH.pqr"), no_h);
  EXPECT_EQ(heavy.atoms.size() + heavy.report.hydrogens_skipped, 8279u);
  EXPECT_GT(heavy.report.hydrogens_skipped, 3000u);

  // 4EY4: 89 residues' atoms in alternate locations A and B; only A is kept.
  const Molecule ache = read_molecule(test::shared_data("molecules/4EY4.pdb"));
  EXPECT_EQ(ache.report.altloc_skipped, 89u);
  EXPECT_EQ(ache.atoms.size(), 8373u - 89u);
  EXPECT_EQ(ache.report.hetatm_skipped + ache.report.water_skipped, 532u);
  EXPECT_EQ(ache.report.default_radius_atoms, 0u);

  // 1UBQ: pre-1996 columns 73-80 ("1UBQ  71"): elements come from the atom names.
  const Molecule ubq = read_molecule(test::shared_data("molecules/1UBQ.pdb"));
  EXPECT_EQ(ubq.atoms.size(), 602u);
  EXPECT_EQ(ubq.report.water_skipped, 58u);
  EXPECT_EQ(ubq.report.default_radius_atoms, 0u);
  EXPECT_EQ(ubq.atoms[0].element, "N");
  EXPECT_EQ(ubq.atoms[1].element, "C");  // " CA " is the alpha carbon
  EXPECT_DOUBLE_EQ(ubq.atoms[1].radius, 1.70);
  EXPECT_DOUBLE_EQ(ubq.atoms[0].center.x(), 27.340);
  EXPECT_DOUBLE_EQ(ubq.atoms[0].center.y(), 24.430);
  EXPECT_DOUBLE_EQ(ubq.atoms[0].center.z(), 2.614);
  MoleculeReadOptions water;
  water.water = true;
  EXPECT_EQ(read_molecule(test::shared_data("molecules/1UBQ.pdb"), water).atoms.size(), 660u);
}

TEST(Molecule, PdbElementFromNameWhenColumnsAreBlank) {
  const std::string text = pdb_line("ATOM", " CA ", "GLY", 1, 2, 3) +         // carbon (blank element)
                           pdb_line("ATOM", "HD21", "ASN", 0, 0, 0) +         // 4-character hydrogen name
                           pdb_line("ATOM", "1HB ", "ALA", 0, 0, 0) +         // digit first: hydrogen
                           pdb_line("HETATM", "FE  ", "HEM", 0, 0, 0) +       // two-letter element
                           pdb_line("HETATM", "CA  ", "CA", 0, 0, 0) +        // calcium, not carbon
                           pdb_line("ATOM", " SG ", "CYS", 0, 0, 0, "S") +    // element column used
                           pdb_line("ATOM", " N  ", "GLY", 0, 0, 0, "  ");
  MoleculeReadOptions opt;
  opt.hetatm = true;
  const Molecule m = parse_pdb(text, "t.pdb", opt);
  ASSERT_EQ(m.atoms.size(), 7u);
  EXPECT_EQ(m.atoms[0].element, "C");
  EXPECT_DOUBLE_EQ(m.atoms[0].radius, 1.70);
  EXPECT_DOUBLE_EQ(m.atoms[0].center.z(), 3.0);
  EXPECT_EQ(m.atoms[1].element, "H");
  EXPECT_TRUE(m.atoms[1].hydrogen);
  EXPECT_EQ(m.atoms[2].element, "H");
  EXPECT_EQ(m.atoms[3].element, "FE");
  EXPECT_EQ(m.atoms[4].element, "CA");
  EXPECT_EQ(m.atoms[5].element, "S");
  EXPECT_EQ(m.atoms[6].element, "N");
  EXPECT_EQ(m.atoms[6].line, 7u);
  // Neither iron nor calcium has a Bondi radius: default radius, counted once per element.
  EXPECT_EQ(m.report.default_radius_atoms, 2u);
  EXPECT_EQ(m.report.unknown_elements, (std::vector<std::string>{"FE", "CA"}));
  EXPECT_DOUBLE_EQ(m.atoms[3].radius, opt.default_radius);
}

TEST(Molecule, PdbAltLocKeepsEachResiduesFirstLocation) {
  const std::string text = pdb_line("ATOM", " N  ", "SER", 0, 0, 0, "N", ' ', 5) +
                           pdb_line("ATOM", " CB ", "SER", 1, 0, 0, "C", 'B', 5) +  // B seen first here
                           pdb_line("ATOM", " CB ", "SER", 2, 0, 0, "C", 'A', 5) +
                           pdb_line("ATOM", " OG ", "SER", 3, 0, 0, "O", 'A', 5) +
                           pdb_line("ATOM", " OG ", "SER", 4, 0, 0, "O", 'B', 5) +
                           pdb_line("ATOM", " CB ", "ALA", 5, 0, 0, "C", 'A', 6) +  // another residue
                           pdb_line("ATOM", " CB ", "ALA", 6, 0, 0, "C", 'B', 6);
  const Molecule m = parse_pdb(text, "t.pdb");
  EXPECT_EQ(m.report.atom_records, 7u);
  EXPECT_EQ(m.report.altloc_skipped, 3u);
  ASSERT_EQ(m.atoms.size(), 4u);
  EXPECT_EQ(m.atoms[0].center.x(), 0.0);
  EXPECT_EQ(m.atoms[1].center.x(), 1.0);
  EXPECT_EQ(m.atoms[2].center.x(), 4.0);
  EXPECT_EQ(m.atoms[3].center.x(), 5.0);
}

TEST(Molecule, PdbFirstModelOnly) {
  const std::string text = "MODEL        1\n" + pdb_line("ATOM", " CA ", "GLY", 0, 0, 0, "C") + "ENDMDL\n" +
                           "MODEL        2\n" + pdb_line("ATOM", " CA ", "GLY", 9, 9, 9, "C") + "ENDMDL\nEND\n";
  const Molecule m = parse_pdb(text, "t.pdb");
  ASSERT_EQ(m.atoms.size(), 1u);
  EXPECT_EQ(m.atoms[0].center.x(), 0.0);
  EXPECT_EQ(m.report.later_model_records, 1u);
}

TEST(Molecule, HetatmWaterAndHydrogenSwitches) {
  const std::string text = pdb_line("ATOM", " CA ", "GLY", 0, 0, 0, "C") + pdb_line("ATOM", " H  ", "GLY", 0, 0, 0, "H") +
                           pdb_line("HETATM", " C1 ", "NAG", 0, 0, 0, "C") + pdb_line("HETATM", " O  ", "HOH", 0, 0, 0, "O") +
                           pdb_line("HETATM", " O  ", "WAT", 0, 0, 0, "O");
  auto count = [&](bool het, bool water, bool hydrogens) {
    MoleculeReadOptions o;
    o.hetatm = het;
    o.water = water;
    o.hydrogens = hydrogens;
    return parse_pdb(text, "t.pdb", o).atoms.size();
  };
  EXPECT_EQ(count(false, false, true), 2u);
  EXPECT_EQ(count(true, false, true), 3u);
  EXPECT_EQ(count(false, true, true), 4u);  // water is independent of --hetatm
  EXPECT_EQ(count(true, true, true), 5u);
  EXPECT_EQ(count(true, true, false), 4u);
  const Molecule m = parse_pdb(text, "t.pdb");
  EXPECT_EQ(m.report.hetatm_skipped, 1u);
  EXPECT_EQ(m.report.water_skipped, 2u);
}

TEST(Molecule, PqrWithAndWithoutChain) {
  const std::string text =
      "REMARK   generated\n"
      "ATOM      1  N   NTER    4     -36.576 -12.088 -13.641  0.185 1.824\n"
      "ATOM      2  HT1 NTER A  4     -36.433 -11.465 -14.423  0.190 1.000\n"
      "HETATM    3  O   HOH     5       1.0 2.0 3.0 -0.8 1.6\n"
      "ATOM      4  HB  ALA     6       0 0 0 0.1 0\n"
      "TER\nEND\n";
  MoleculeReadOptions o;
  o.water = true;
  const Molecule m = parse_pqr(text, "t.pqr", o);
  ASSERT_EQ(m.atoms.size(), 3u);
  EXPECT_DOUBLE_EQ(m.atoms[0].radius, 1.824);
  EXPECT_DOUBLE_EQ(m.atoms[1].center.z(), -14.423);
  EXPECT_TRUE(m.atoms[1].hydrogen);
  EXPECT_TRUE(m.atoms[2].water);
  EXPECT_EQ(m.report.zero_radius_skipped, 1u);
  EXPECT_EQ(m.report.hetatm_records, 1u);
}

TEST(Molecule, MalformedLinesNameFileLineAndField) {
  std::string bad = pdb_line("ATOM", " CA ", "GLY", 0, 0, 0, "C") + pdb_line("ATOM", " CB ", "GLY", 0, 0, 0, "C");
  bad.replace(bad.find('\n') + 1 + 38, 8, "  12.x45");  // y of line 2
  EXPECT_EQ(error_of([&] { parse_pdb(bad, "m.pdb"); }),
            "m.pdb: line 2: y coordinate (columns 39-46): '12.x45' is not a number");
  EXPECT_EQ(error_of([&] { parse_pdb("HEADER\nATOM      1  CA  GLY A   1      11.000  12.000\n", "m.pdb"); }),
            "m.pdb: line 2: z coordinate (columns 47-54): the line ends at column 46");
  EXPECT_EQ(error_of([&] { parse_pqr("ATOM 1 N GLY 1 0 0 0 0.1\n", "m.pqr"); }),
            "m.pqr: line 1: expected 10 or 11 fields (ATOM serial atomName resName [chain] resSeq x y z charge "
            "radius), found 9");
  EXPECT_EQ(error_of([&] { parse_pqr("\nATOM 1 N GLY 1 0 0 0 0.1 big\n", "m.pqr"); }),
            "m.pqr: line 2: field 10 (radius): 'big' is not a number");
  EXPECT_EQ(error_of([&] { parse_pqr("ATOM 1 N GLY 1 0 0 0 0.1 -1\n", "m.pqr"); }),
            "m.pqr: line 1: field 10 (radius): -1 is negative");
  EXPECT_NE(error_of([&] { read_molecule("x.xyz"); }).find("unknown molecule format"), std::string::npos);
  EXPECT_NE(error_of([&] { read_molecule("/nonexistent/x.pdb"); }).find("cannot open"), std::string::npos);
}

TEST(Density, SingleAtomFollowsTheFormulaAndCrossesOneAtItsRadius) {
  Atom a;
  a.center = Vec3(0.13, -0.27, 0.31);  // off the grid
  a.radius = 1.6;
  const std::vector<Atom> atoms{a};
  DensityOptions o;
  o.spacing = 0.25;
  o.blobbiness = 0.7;
  DensityReport rep;
  const Volume v = gaussian_density(atoms, o, &rep);
  EXPECT_LT(rep.boundary_max, 1.0);
  EXPECT_DOUBLE_EQ(gaussian_density_at(atoms, o.blobbiness, a.center + Vec3(0, a.radius, 0)), 1.0);
  EXPECT_NEAR(gaussian_density_at(atoms, o.blobbiness, a.center), std::exp(0.7), 1e-15);
  const double cut = rep.cutoff_factor * a.radius;
  std::size_t inside = 0;
  for (Index k = 0; k < v.dims[2]; ++k)
    for (Index j = 0; j < v.dims[1]; ++j)
      for (Index i = 0; i < v.dims[0]; ++i) {
        const double d = (v.point(i, j, k) - a.center).norm();
        const double expected = std::exp(-0.7 * (d * d / (1.6 * 1.6) - 1));
        const float got = v.at(i, j, k);
        if (d <= cut * (1 - 1e-9)) {
          ASSERT_NEAR(got, expected, 1e-6 * expected) << i << " " << j << " " << k;
        } else {
          ASSERT_TRUE(got == 0.0f || d < cut * (1 + 1e-9)) << "touched beyond the cut-off";
        }
        // Above 1 exactly inside the radius (away from float round-off at the surface).
        if (std::abs(d - a.radius) > 1e-5) ASSERT_EQ(got > 1.0f, d < a.radius) << d;
        inside += got > 1.0f;
      }
  // The inside points fill the ball's volume, to grid resolution.
  const double ball = 4.0 / 3.0 * M_PI * std::pow(a.radius, 3) / std::pow(o.spacing, 3);
  EXPECT_NEAR(double(inside), ball, 0.05 * ball);
  // The grid covers the sphere plus padding.
  for (int d = 0; d < 3; ++d) {
    EXPECT_LE(v.origin[d], a.center[d] - a.radius - o.padding + 1e-12);
    EXPECT_GE(v.max_corner()[d], a.center[d] + a.radius + o.padding - 1e-12);
    EXPECT_LT(v.max_corner()[d], a.center[d] + a.radius + o.padding + o.spacing);
  }
}

// Max |cut-off density - exact sum| over every grid point.
double max_truncation_error(const std::vector<Atom>& atoms, const DensityOptions& o) {
  const Volume v = gaussian_density(atoms, o);
  double worst = 0;
  for (Index k = 0; k < v.dims[2]; ++k)
    for (Index j = 0; j < v.dims[1]; ++j)
      for (Index i = 0; i < v.dims[0]; ++i)
        worst = std::max(worst, std::abs(gaussian_density_at(atoms, o.blobbiness, v.point(i, j, k)) - v.at(i, j, k)));
  return worst;
}

TEST(Density, CutOffErrorStaysBelowEpsilonOnUbiquitin) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const Molecule m = read_molecule(test::shared_data("molecules/1UBQ.pdb"));
  DensityOptions o;
  o.spacing = 1.0;
  const double err = max_truncation_error(m.atoms, o);
  EXPECT_LT(err, o.epsilon);
  EXPECT_GT(err, 0.0);  // there is a cut-off at all
  o.epsilon = 1e-5;
  EXPECT_LT(max_truncation_error(m.atoms, o), 1e-5);
}

// A random, protein-dense cluster (0.1 atoms/Å³) that needs no shared data.
std::vector<Atom> random_cluster(std::size_t n, unsigned seed) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<double> pos(-1, 1), rad(1.0, 2.0);
  const double half = 0.5 * std::cbrt(double(n) / 0.1);
  std::vector<Atom> atoms(n);
  for (Atom& a : atoms) {
    a.center = half * Vec3(pos(g), pos(g), pos(g));
    a.radius = rad(g);
  }
  return atoms;
}

TEST(Density, CutOffErrorStaysBelowEpsilonInADenseCluster) {
  DensityOptions o;
  o.spacing = 0.8;
  EXPECT_LT(max_truncation_error(random_cluster(1500, 7), o), o.epsilon);
}

TEST(Density, BitIdenticalForAnyThreadCount) {
  const std::vector<Atom> atoms = random_cluster(3000, 11);
  DensityOptions o;
  o.spacing = 0.4;
  std::vector<float> reference;
  for (std::size_t threads : {1, 2, 3, 8}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    const Volume v = gaussian_density(atoms, o);
    if (reference.empty()) reference = v.values;
    else ASSERT_TRUE(v.values == reference) << threads << " threads";
  }
}

TEST(Density, RejectsBadOptionsAndNoAtoms) {
  const std::vector<Atom> atoms = random_cluster(3, 1);
  DensityOptions o;
  o.spacing = 0;
  EXPECT_NE(error_of([&] { gaussian_density(atoms, o); }).find("spacing"), std::string::npos);
  o = {};
  o.blobbiness = -1;
  EXPECT_NE(error_of([&] { gaussian_density(atoms, o); }).find("blobbiness"), std::string::npos);
  o = {};
  o.spacing = 1e-4;
  EXPECT_NE(error_of([&] { gaussian_density(atoms, o); }).find("2^31"), std::string::npos);
  EXPECT_NE(error_of([&] { gaussian_density(std::vector<Atom>{}); }).find("no atoms"), std::string::npos);
}

std::string file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST(MoleculeCli, WritesTheDensityTheLibraryComputes) {
  ISOHEX_REQUIRE_SHARED_DATA();
  const auto dir = test::scratch_dir();
  const auto pdb = test::shared_data("molecules/1UBQ.pdb");
  std::string out;
  ASSERT_EQ(test::run_cli(fmt::format("volume molecule '{}' -o '{}' --spacing 1 --threads 1", pdb.string(),
                                      (dir / "a.nrrd").string()),
                          &out),
            0)
      << out;
  EXPECT_NE(out.find("atoms used   602"), std::string::npos) << out;
  EXPECT_NE(out.find("58 water atoms"), std::string::npos) << out;
  EXPECT_NE(out.find("suggested isovalue 1.0"), std::string::npos) << out;
  ASSERT_EQ(test::run_cli(fmt::format("volume molecule '{}' -o '{}' --spacing 1 --threads 2", pdb.string(),
                                      (dir / "b.nrrd").string())),
            0);
  EXPECT_EQ(file_bytes(dir / "a.nrrd"), file_bytes(dir / "b.nrrd"));

  DensityOptions o;
  o.spacing = 1;
  const Volume expected = gaussian_density(read_molecule(pdb).atoms, o);
  const Volume got = read_volume(dir / "a.nrrd");
  EXPECT_EQ(got.dims, expected.dims);
  EXPECT_TRUE(got.origin.isApprox(expected.origin, 1e-12));
  EXPECT_TRUE(got.values == expected.values);

  // Options reach the reader and the density.
  ASSERT_EQ(test::run_cli(fmt::format("volume molecule '{}' -o '{}' --spacing 1.5 --padding 1 --blobbiness 1 --water",
                                      pdb.string(), (dir / "c.vti").string()),
                          &out),
            0)
      << out;
  EXPECT_NE(out.find("atoms used   660"), std::string::npos) << out;
  MoleculeReadOptions water;
  water.water = true;
  o = {};
  o.spacing = 1.5;
  o.padding = 1;
  o.blobbiness = 1;
  EXPECT_TRUE(read_volume(dir / "c.vti").values == gaussian_density(read_molecule(pdb, water).atoms, o).values);
}

TEST(MoleculeCli, ErrorsNameFileAndLine) {
  const auto dir = test::scratch_dir();
  {
    std::ofstream f(dir / "bad.pqr");
    f << "ATOM 1 N GLY 1 0 0 0 0.1 1.5\nATOM 2 C GLY 1 0 zero 0 0.1 1.7\n";
  }
  std::string out;
  EXPECT_EQ(test::run_cli(fmt::format("volume molecule '{}' -o '{}'", (dir / "bad.pqr").string(),
                                      (dir / "x.nrrd").string()),
                          &out),
            2);
  EXPECT_NE(out.find("bad.pqr: line 2: field 7 (y): 'zero' is not a number"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.nrrd"));
  EXPECT_EQ(test::run_cli(fmt::format("volume molecule '{}' -o '{}'", (dir / "bad.pqr").string(),
                                      (dir / "x.png").string()),
                          &out),
            2);
  EXPECT_NE(out.find("cannot write volume format '.png'"), std::string::npos) << out;
}

}  // namespace
}  // namespace isohex
