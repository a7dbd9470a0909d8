// PDB and PQR readers: atoms, radii and the HETATM / water / hydrogen / altLoc filters.
#include "isohex/volume/molecule.hpp"

#include "isohex/error.hpp"
#include "isohex/io/format_support.hpp"
#include "isohex/io/text_scanner.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

namespace isohex {

namespace {

struct BondiEntry {
  std::string_view element;
  double radius;
};

// Bondi, "van der Waals Volumes and Radii", J. Phys. Chem. 68 (1964) 441.
constexpr std::array<BondiEntry, 38> kBondi = {{
    {"H", 1.20},  {"HE", 1.40}, {"LI", 1.82}, {"C", 1.70},  {"N", 1.55},  {"O", 1.52},  {"F", 1.47},
    {"NE", 1.54}, {"NA", 2.27}, {"MG", 1.73}, {"SI", 2.10}, {"P", 1.80},  {"S", 1.80},  {"CL", 1.75},
    {"AR", 1.88}, {"K", 2.75},  {"NI", 1.63}, {"CU", 1.40}, {"ZN", 1.39}, {"GA", 1.87}, {"AS", 1.85},
    {"SE", 1.90}, {"BR", 1.85}, {"KR", 2.02}, {"PD", 1.63}, {"AG", 1.72}, {"CD", 1.58}, {"IN", 1.93},
    {"SN", 2.17}, {"TE", 2.06}, {"I", 1.98},  {"XE", 2.16}, {"PT", 1.72}, {"AU", 1.66}, {"HG", 1.55},
    {"TL", 1.96}, {"PB", 2.02}, {"U", 1.86},
}};

// Two-letter element symbols, to tell "FE  " (iron) from "HD21" (a hydrogen) in atom names.
constexpr std::string_view kTwoLetterElements =
    " HE LI BE NE NA MG AL SI CL AR CA SC TI CR MN FE CO NI CU ZN GA GE AS SE BR KR RB SR ZR NB MO TC"
    " RU RH PD AG CD IN SN SB TE XE CS BA LA CE PR ND PM SM EU GD TB DY HO ER TM YB LU HF TA RE OS IR"
    " PT AU HG TL PB BI PO AT RN FR RA AC TH PA NP PU AM CM BK CF ES FM MD NO LR ";

bool is_two_letter_element(std::string_view s) {
  return s.size() == 2 && kTwoLetterElements.find(fmt::format(" {} ", s)) != std::string_view::npos;
}

bool is_water(std::string_view res) {
  for (std::string_view w : {"HOH", "WAT", "H2O", "DOD", "TIP", "TIP3", "TIP4", "SOL", "SPC"})
    if (res == w) return true;
  return false;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  return s;
}

std::string upper(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

bool all_letters(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return std::isalpha(static_cast<unsigned char>(c)); });
}

// Columns [first, last] (1-based, inclusive) of a line, clipped to its length.
std::string_view columns(std::string_view line, std::size_t first, std::size_t last) {
  if (line.size() < first) return {};
  return line.substr(first - 1, std::min(last, line.size()) - (first - 1));
}

// The element a PDB atom name (columns 13-16, padded to 4) implies.
std::string element_from_name(std::string_view name, bool hetatm) {
  const auto c0 = static_cast<unsigned char>(name[0]);
  if (c0 == ' ' || std::isdigit(c0)) return upper(name.substr(1, 1));
  const std::string two = upper(name.substr(0, 2));
  if (hetatm && is_two_letter_element(two)) return two;
  return two.substr(0, 1);
}

// Applies the keep/skip options to an atom, counting what it drops; true to keep it.
bool keep_atom(const Atom& a, const MoleculeReadOptions& opt, MoleculeReadReport& rep) {
  if (a.water && !opt.water) {
    ++rep.water_skipped;
    return false;
  }
  if (!a.water && a.hetatm && !opt.hetatm) {
    ++rep.hetatm_skipped;
    return false;
  }
  if (a.hydrogen && !opt.hydrogens) {
    ++rep.hydrogens_skipped;
    return false;
  }
  return true;
}

// Calls f(line, line_number) for each line of `text` (without '\n' or a trailing '\r').
template <class F>
void for_each_line(std::string_view text, F&& f) {
  std::size_t number = 0;
  while (!text.empty()) {
    const std::size_t end = std::min(text.find('\n'), text.size());
    std::string_view line = text.substr(0, end);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    f(line, ++number);
    text.remove_prefix(std::min(end + 1, text.size()));
  }
}

[[noreturn]] void line_error(const std::filesystem::path& file, std::size_t line, std::string_view what) {
  io::parse_error(file, fmt::format("line {}", line), what);
}

double pdb_coordinate(const std::filesystem::path& file, std::size_t number, std::string_view line, char axis,
                      std::size_t first) {
  const std::size_t last = first + 7;
  if (line.size() < last)
    line_error(file, number,
               fmt::format("{} coordinate (columns {}-{}): the line ends at column {}", axis, first, last, line.size()));
  const std::string_view field = trim(columns(line, first, last));
  double v = 0;
  if (!io::parse_double(field, v))
    line_error(file, number,
               fmt::format("{} coordinate (columns {}-{}): '{}' is not a number", axis, first, last, io::printable(field)));
  return v;
}

void note_default_radius(MoleculeReadReport& rep, const std::string& element) {
  ++rep.default_radius_atoms;
  if (std::find(rep.unknown_elements.begin(), rep.unknown_elements.end(), element) == rep.unknown_elements.end())
    rep.unknown_elements.push_back(element);
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot open for reading", file.string()));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw Error(fmt::format("{}: read error", file.string()));
  return std::move(ss).str();
}

}  // namespace

std::optional<double> bondi_radius(std::string_view element) {
  if (element == "D") element = "H";
  for (const BondiEntry& e : kBondi)
    if (e.element == element) return e.radius;
  return std::nullopt;
}

Molecule parse_pdb(std::string_view text, const std::filesystem::path& file, const MoleculeReadOptions& opt) {
  Molecule mol;
  MoleculeReadReport& rep = mol.report;
  bool in_later_model = false, seen_model = false;
  // Per residue (chain, resSeq, iCode = columns 22-27): the first alternate location seen.
  std::map<std::string, char, std::less<>> residue_altloc;
  for_each_line(text, [&](std::string_view line, std::size_t number) {
    const std::string_view record = columns(line, 1, 6);
    if (record == "ENDMDL") {
      in_later_model = true;
      return;
    }
    if (record.starts_with("MODEL")) {
      if (seen_model) in_later_model = true;  // a second MODEL without ENDMDL before it
      seen_model = true;
      return;
    }
    const bool atom = record == "ATOM  " || record == "ATOM";
    const bool hetatm = record == "HETATM";
    if (!atom && !hetatm) return;
    if (in_later_model) {
      ++rep.later_model_records;
      return;
    }
    ++(atom ? rep.atom_records : rep.hetatm_records);

    const char altloc = line.size() >= 17 ? line[16] : ' ';
    if (altloc != ' ') {
      const std::string key(columns(line, 22, 27));
      auto [it, inserted] = residue_altloc.try_emplace(key, altloc);
      if (!inserted && it->second != altloc) {
        ++rep.altloc_skipped;
        return;
      }
    }

    Atom a;
    a.line = number;
    a.hetatm = hetatm;
    a.center = Vec3(pdb_coordinate(file, number, line, 'x', 31), pdb_coordinate(file, number, line, 'y', 39),
                    pdb_coordinate(file, number, line, 'z', 47));
    a.water = is_water(trim(columns(line, 18, 21)));
    const std::string_view element = trim(columns(line, 77, 78));
    if (all_letters(element)) {
      a.element = upper(element);
    } else {
      std::string name(columns(line, 13, 16));
      name.resize(4, ' ');
      if (trim(name).empty()) line_error(file, number, "atom name (columns 13-16) is blank and so is the element (columns 77-78)");
      a.element = element_from_name(name, hetatm);
      if (!all_letters(a.element))
        line_error(file, number,
                   fmt::format("atom name (columns 13-16) '{}' names no element and the element (columns 77-78) is blank",
                               io::printable(trim(name))));
    }
    a.hydrogen = a.element == "H" || a.element == "D";
    if (!keep_atom(a, opt, rep)) return;
    if (auto r = bondi_radius(a.element)) {
      a.radius = *r;
    } else {
      a.radius = opt.default_radius;
      note_default_radius(rep, a.element);
    }
    mol.atoms.push_back(std::move(a));
    return;
  });
  return mol;
}

Molecule parse_pqr(std::string_view text, const std::filesystem::path& file, const MoleculeReadOptions& opt) {
  Molecule mol;
  MoleculeReadReport& rep = mol.report;
  for_each_line(text, [&](std::string_view line, std::size_t number) {
    std::vector<std::string_view> f;
    for (std::size_t p = 0; p < line.size();) {
      while (p < line.size() && std::isspace(static_cast<unsigned char>(line[p]))) ++p;
      const std::size_t start = p;
      while (p < line.size() && !std::isspace(static_cast<unsigned char>(line[p]))) ++p;
      if (p > start) f.push_back(line.substr(start, p - start));
    }
    if (f.empty()) return;
    const bool atom = f[0] == "ATOM", hetatm = f[0] == "HETATM";
    if (!atom && !hetatm) return;
    ++(atom ? rep.atom_records : rep.hetatm_records);
    if (f.size() != 10 && f.size() != 11)
      line_error(file, number,
                 fmt::format("expected 10 or 11 fields ({} serial atomName resName [chain] resSeq x y z charge radius), "
                             "found {}",
                             f[0], f.size()));
    const std::size_t n = f.size();
    auto number_field = [&](std::size_t i, std::string_view what) {
      double v = 0;
      if (!io::parse_double(f[i], v))
        line_error(file, number, fmt::format("field {} ({}): '{}' is not a number", i + 1, what, io::printable(f[i])));
      return v;
    };
    Atom a;
    a.line = number;
    a.hetatm = hetatm;
    a.center = Vec3(number_field(n - 5, "x"), number_field(n - 4, "y"), number_field(n - 3, "z"));
    number_field(n - 2, "charge");
    a.radius = number_field(n - 1, "radius");
    if (a.radius < 0)
      line_error(file, number, fmt::format("field {} (radius): {} is negative", n, io::printable(f[n - 1])));
    const std::string_view name = f[2];
    const std::size_t first = name.find_first_not_of("0123456789");
    a.element = first == std::string_view::npos ? std::string() : upper(name.substr(first, 1));
    a.hydrogen = a.element == "H";
    a.water = is_water(f[3]);
    if (!keep_atom(a, opt, rep)) return;
    if (a.radius == 0) {
      ++rep.zero_radius_skipped;
      return;
    }
    mol.atoms.push_back(std::move(a));
    return;
  });
  return mol;
}

Molecule read_molecule(const std::filesystem::path& file, const MoleculeReadOptions& options) {
  const std::string ext = upper(file.extension().string());
  if (ext != ".PDB" && ext != ".ENT" && ext != ".PQR")
    throw Error(fmt::format("{}: unknown molecule format '{}' (expected .pdb, .ent or .pqr)", file.string(),
                            file.extension().string()));
  if (!(options.default_radius > 0))
    throw Error(fmt::format("default atom radius {} is not positive", options.default_radius));
  const std::string text = read_text(file);
  Molecule mol = ext == ".PQR" ? parse_pqr(text, file, options) : parse_pdb(text, file, options);
  if (mol.report.atom_records + mol.report.hetatm_records == 0)
    throw Error(fmt::format("{}: no ATOM or HETATM records", file.string()));
  return mol;
}

}  // namespace isohex
