// isohex volume molecule IN.pdb|IN.pqr -o OUT: the blobby Gaussian density map of a molecule.
#include "commands.hpp"

#include "isohex/error.hpp"
#include "isohex/volume/molecule.hpp"
#include "isohex/volume/volume_io.hpp"

#include <fmt/format.h>

#include <cctype>
#include <chrono>
#include <filesystem>
#include <memory>

namespace isohex::cli {

namespace {

struct Args {
  std::string input, output;
  DensityOptions density;
  bool hetatm = false, water = false, no_hydrogens = false;
  int* threads = nullptr;
};

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

void print_read_report(const Molecule& m) {
  const MoleculeReadReport& r = m.report;
  fmt::print("  records      {} ATOM, {} HETATM\n", r.atom_records, r.hetatm_records);
  fmt::print("  atoms used   {}\n", m.atoms.size());
  auto skipped = [](std::size_t n, std::string_view what) {
    if (n) fmt::print("  skipped      {} {}\n", n, what);
  };
  skipped(r.altloc_skipped, "alternate-location atoms (each residue keeps its first location)");
  skipped(r.later_model_records, "records of later models (only the first MODEL is read)");
  skipped(r.hetatm_skipped, "HETATM atoms (--hetatm keeps them)");
  skipped(r.water_skipped, "water atoms (--water keeps them)");
  skipped(r.hydrogens_skipped, "hydrogens (--no-hydrogens)");
  skipped(r.zero_radius_skipped, "atoms of radius 0");
  if (r.default_radius_atoms)
    fmt::print("  warning: {} atoms of elements without a Bondi radius ({}) got the default radius {} Å\n",
               r.default_radius_atoms, fmt::join(r.unknown_elements, " "), MoleculeReadOptions{}.default_radius);
}

void run(const Args& a) {
  ThreadLimit limit(*a.threads);
  require_volume_output(a.output);
  const auto start = std::chrono::steady_clock::now();
  MoleculeReadOptions read;
  read.hetatm = a.hetatm;
  read.water = a.water;
  read.hydrogens = !a.no_hydrogens;
  const Molecule m = read_molecule(a.input, read);
  const double read_time = seconds_since(start);
  fmt::print("{}\n", a.input);
  print_read_report(m);

  const auto density_start = std::chrono::steady_clock::now();
  DensityReport rep;
  const Volume v = gaussian_density(m.atoms, a.density, &rep);
  const double density_time = seconds_since(density_start);
  const Vec3 far = v.max_corner();
  fmt::print("  density      exp(-B (d^2/r^2 - 1)), B = {}, cut-off {:.3g} radii (error < {:g})\n",
             a.density.blobbiness, rep.cutoff_factor, a.density.epsilon);
  fmt::print("  dims         {} x {} x {} ({} points), spacing {} Å\n", v.dims[0], v.dims[1], v.dims[2], v.size(),
             a.density.spacing);
  fmt::print("  bounds       ({:.4g}, {:.4g}, {:.4g}) to ({:.4g}, {:.4g}, {:.4g}) Å\n", v.origin.x(), v.origin.y(),
             v.origin.z(), far.x(), far.y(), far.z());
  if (rep.boundary_max >= kMoleculeIsovalue)
    fmt::print("  warning: the density reaches {:.3g} on the grid boundary, so the surface is cut open there; "
               "increase --padding\n",
               rep.boundary_max);
  write_volume(a.output, v);
  fmt::print("  time         read {:.3f} s, density {:.3f} s ({} atom-point terms), total {:.3f} s\n", read_time,
             density_time, rep.voxels_touched, seconds_since(start));
  fmt::print("wrote {}; suggested isovalue {:.1f} (the molecular surface; inside is above it)\n", a.output,
             kMoleculeIsovalue);
}

}  // namespace

void register_volume_molecule(CLI::App& volume) {
  auto a = std::make_shared<Args>();
  CLI::App* cmd = volume.add_subcommand("molecule", "Blobby Gaussian density map of a molecule (.pdb, .pqr)");
  cmd->add_option("input", a->input, "Molecule: PDB (.pdb, .ent; Bondi radii by element) or PQR (.pqr; its radii)")
      ->required();
  cmd->add_option("-o,--output", a->output, "Output volume (.nrrd or .vti)")->required();
  cmd->add_option("--spacing", a->density.spacing, "Grid spacing in Å (default 0.5)")->check(CLI::PositiveNumber);
  cmd->add_option("--padding", a->density.padding,
                  "Space around the atoms' spheres in Å (default 3)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--blobbiness", a->density.blobbiness,
                  "B in exp(-B (d^2/r^2 - 1)); smaller is smoother (default 0.5)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--epsilon", a->density.epsilon,
                  "Bound on the error of cutting each atom's Gaussian off (default 1e-3)")
      ->check(CLI::Range(1e-12, 0.5));
  cmd->add_flag("--hetatm", a->hetatm, "Keep HETATM records (ligands, ions); water is governed by --water");
  cmd->add_flag("--water", a->water, "Keep water molecules (HOH, WAT, H2O, DOD, TIP, TIP3, TIP4, SOL, SPC)");
  cmd->add_flag("--no-hydrogens", a->no_hydrogens, "Leave out hydrogen (and deuterium) atoms");
  a->threads = add_threads_option(cmd);
  cmd->footer(
      "Each atom adds exp(-B (|x-c|^2/r^2 - 1)): 1 at its radius, so the isosurface 1.0 is the molecular\n"
      "surface (inside above 1). PDB: columns 31-54 for x y z, 77-78 for the element (else from the atom\n"
      "name); first model only; each residue keeps its first alternate location. The output is bit-identical\n"
      "for any --threads.");
  cmd->callback([a] { run(*a); });
}

}  // namespace isohex::cli
