#pragma once
/// \file molecule.hpp
/// \brief Molecules (PDB, PQR) and their blobby Gaussian density maps.
///
/// A molecule becomes a Volume through the "blobby" density of Blinn (1982), the kind of
/// map the mAChE mesh of Shepherd et al. (2006) was extracted from:
///
///     G(x) = sum over atoms i of  exp(-B · (|x - c_i|² / r_i² - 1))
///
/// with c_i, r_i the atom's centre and radius and B > 0 the blobbiness. A lone atom's
/// term is exp(B) at its centre and exactly 1 at distance r_i, so the isosurface
/// G = 1 (kMoleculeIsovalue) is the molecular surface: each atom's van der Waals sphere,
/// smoothly merged with its neighbours'. Inside is **above** the isovalue.
///
/// Readers:
///  - PDB: fixed columns. ATOM and HETATM records; x 31-38, y 39-46, z 47-54, element
///    77-78. When the element columns are blank or not an element symbol (old files
///    such as 1UBQ carry an ID and serial number in columns 73-80) the element comes from
///    the atom name (columns 13-16): a name whose column 13 is blank or a digit holds a
///    one-letter element in column 14 (" CA " is carbon, "1HB " hydrogen); a name starting
///    in column 13 is a two-letter element in HETATM records when the two letters are one
///    ("FE  ", "ZN  "), otherwise its first letter ("HD21" is hydrogen).
///    Alternate locations (column 17): per residue, only the first alternate-location
///    identifier seen is kept, so one consistent conformer remains. MODEL/ENDMDL: only the
///    first model is read. Radii: Bondi (1964) van der Waals radii by element; an element
///    without one gets MoleculeReadOptions::default_radius and is counted.
///  - PQR (APBS, PDB2PQR): whitespace-separated
///    `ATOM|HETATM serial atomName resName [chain] resSeq x y z charge radius`, radii taken
///    as given. An atom is a hydrogen when its name's first non-digit character is H.
///    Atoms of radius 0 (some force fields give hydrogens none) add no density and are
///    skipped and counted.
///
/// Errors throw isohex::Error "FILE: line N: <field>: <what is wrong>".

#include "isohex/volume/volume.hpp"

#include <cstddef>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace isohex {

/// One atom, as the density map needs it.
struct Atom {
  Vec3 center{0, 0, 0};  ///< position (Å)
  double radius = 0;     ///< radius (Å), > 0
  std::string element;   ///< element symbol, upper case ("C", "FE"); for PQR from the atom name
  bool hetatm = false;   ///< read from a HETATM record
  bool water = false;    ///< residue HOH, WAT, H2O, DOD, TIP, TIP3, TIP4, SOL or SPC
  bool hydrogen = false; ///< element H or D
  std::size_t line = 0;  ///< 1-based line of the record in the file
};

/// Which atoms a reader keeps.
struct MoleculeReadOptions {
  bool hetatm = false;     ///< keep HETATM records (other than water: see `water`)
  bool water = false;      ///< keep water residues, whether ATOM or HETATM records
  bool hydrogens = true;   ///< keep hydrogen (and deuterium) atoms
  /// PDB radius for elements without a Bondi radius (Å): close to C, S and P, the heavy
  /// atoms that dominate biomolecules, so an unknown atom neither vanishes nor swells.
  double default_radius = 1.8;
};

/// What a reader saw and dropped.
struct MoleculeReadReport {
  std::size_t atom_records = 0;        ///< ATOM records of the first model (all alt. locations)
  std::size_t hetatm_records = 0;      ///< HETATM records of the first model
  std::size_t altloc_skipped = 0;      ///< records of a residue's second, third... alternate location
  std::size_t later_model_records = 0; ///< ATOM/HETATM records after the first model, ignored
  std::size_t hetatm_skipped = 0;      ///< non-water HETATM atoms left out (no `hetatm`)
  std::size_t water_skipped = 0;       ///< water atoms left out (no `water`)
  std::size_t hydrogens_skipped = 0;   ///< hydrogens left out (no `hydrogens`)
  std::size_t zero_radius_skipped = 0; ///< PQR atoms of radius 0, which add no density
  std::size_t default_radius_atoms = 0;      ///< PDB atoms given the default radius
  std::vector<std::string> unknown_elements; ///< their distinct elements, in order of appearance
};

/// A molecule: the atoms kept, in file order.
struct Molecule {
  std::vector<Atom> atoms;
  MoleculeReadReport report;
};

/// Reads a .pdb/.ent or .pqr file (by extension, any case).
Molecule read_molecule(const std::filesystem::path& file, const MoleculeReadOptions& options = {});

/// Parses PDB text; `file` only names the source in messages.
Molecule parse_pdb(std::string_view text, const std::filesystem::path& file, const MoleculeReadOptions& options = {});

/// Parses PQR text; `file` only names the source in messages.
Molecule parse_pqr(std::string_view text, const std::filesystem::path& file, const MoleculeReadOptions& options = {});

/// Bondi's van der Waals radius of `element` (upper-case symbol; "D" counts as hydrogen),
/// or nothing when Bondi gives none.
std::optional<double> bondi_radius(std::string_view element);

/// The isovalue of the molecular surface in a Gaussian density map.
inline constexpr double kMoleculeIsovalue = 1.0;

/// How to sample the Gaussian density.
struct DensityOptions {
  double spacing = 0.5;  ///< grid spacing (Å), the same along x, y, z
  /// Empty space beyond the atoms' spheres (Å): the merged surface bulges out past the
  /// spheres where atoms crowd, and a mesher needs a layer of outside points around it.
  double padding = 3.0;
  /// B in exp(-B·(d²/r² - 1)). Every B puts a lone atom's surface at its radius; B sets
  /// how far atoms reach into their neighbours' space. Two atoms of radius r merge when
  /// their centres are closer than 2r·sqrt(1 + ln 2 / B): with B = 0.5, carbon spheres
  /// (r = 1.7 Å) fuse across gaps up to 1.9 Å, narrower than a water molecule (2.8 Å), so
  /// crevices the solvent cannot enter fill in and the surface is smooth and close to the
  /// solvent-excluded surface, what a finite-element mesh of a protein wants. Larger B
  /// tends to the bumpy union of van der Waals spheres (B = 1 fuses gaps up to 1.0 Å).
  double blobbiness = 0.5;
  /// Bound on the truncation error: the density differs from the exact sum over all atoms
  /// by less than this anywhere (see gaussian_density()).
  double epsilon = 1e-3;
};

/// What gaussian_density() did.
struct DensityReport {
  double cutoff_factor = 0;        ///< each atom's cut-off radius, in units of its radius
  std::size_t voxels_touched = 0;  ///< atom-voxel contributions summed
  double boundary_max = 0;         ///< largest value on the grid's faces (>= 1: surface cut off)
};

/// The per-atom threshold behind DensityOptions::epsilon: atoms are cut off where their
/// term falls below epsilon · kAtomTailShare. The cut-off tails of all atoms near a point
/// add up: in a protein (about 0.1 atoms/Å³ with hydrogens) they come to tens of atoms'
/// worth. Measured against the exact sum at B = 0.5, epsilon = 1e-3: mAChE (8,279 atoms
/// with hydrogens) errs by at most 1.7e-4 with 1/250 (4.3e-4 with 1/100), so 1/250 keeps
/// the total below epsilon with a margin of about 6.
inline constexpr double kAtomTailShare = 1.0 / 250.0;

/// The cut-off radius, in units of the atom radius, where exp(-B·(d²/r² - 1)) = threshold.
double gaussian_cutoff_factor(double blobbiness, double threshold);

/// The blobby density of `atoms` on a grid of spacing `options.spacing` covering every
/// atom's sphere plus `options.padding`. Each atom adds its term only to the grid points
/// within its cut-off radius; the term is evaluated as a product of three 1-D Gaussians,
/// so a point costs one multiply-add. Parallel over z-slabs with oneTBB; every grid point
/// sums its atoms in atom order, so the result is bit-identical for any thread count.
/// Throws isohex::Error for bad options, no atoms or a grid over 2^31 points.
Volume gaussian_density(std::span<const Atom> atoms, const DensityOptions& options = {},
                        DensityReport* report = nullptr);

/// The exact density at `p`: the sum over all atoms, in double precision (a reference).
double gaussian_density_at(std::span<const Atom> atoms, double blobbiness, const Vec3& p);

}  // namespace isohex
