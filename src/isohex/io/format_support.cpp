#include "isohex/io/format_support.hpp"

#include "isohex/error.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <ostream>

namespace isohex::io {

namespace {
char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }
}  // namespace

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (lower(a[i]) != lower(b[i])) return false;
  return true;
}

bool istarts_with(std::string_view text, std::string_view prefix) {
  return text.size() >= prefix.size() && iequals(text.substr(0, prefix.size()), prefix);
}

std::string printable(std::string_view token) {
  constexpr std::size_t kMax = 40;
  std::string out;
  for (std::size_t i = 0; i < token.size() && i < kMax; ++i) {
    const auto c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f)
      out += static_cast<char>(c);
    else
      out += fmt::format("\\x{:02x}", c);
  }
  if (token.size() > kMax) out += "...";
  return out;
}

namespace {

// Letters, digits and '_', starting with a letter, at most 32 characters: a name every format
// takes as it is (an Abaqus surface, an Exodus set, a VTK array).
bool is_identifier(const std::string& name) {
  return !name.empty() && name.size() <= 32 && std::isalpha(static_cast<unsigned char>(name[0])) &&
         std::all_of(name.begin(), name.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

}  // namespace

void check_fields_for_writing(const std::filesystem::path& file, const HexMesh& mesh, const WriteOptions& options) {
  std::vector<std::string> names = {"block", "fixed"};
  for (const auto* fields : {&options.cell_fields, &options.point_fields})
    for (const DataField& f : *fields) {
      const bool cell = fields == &options.cell_fields;
      const std::size_t want = cell ? mesh.hexes.size() : mesh.points.size();
      if (!is_identifier(f.name))
        throw Error(fmt::format("{}: cannot write: field name '{}' is not letters, digits and '_' starting with a letter",
                                file.string(), f.name));
      if (std::find(names.begin(), names.end(), f.name) != names.end())
        throw Error(fmt::format("{}: cannot write: two arrays named '{}'", file.string(), f.name));
      names.push_back(f.name);
      if (f.values.size() != want)
        throw Error(fmt::format("{}: cannot write: {} field '{}' has {} values for {} {}", file.string(),
                                cell ? "cell" : "point", f.name, f.values.size(), want, cell ? "hexes" : "vertices"));
    }
}

void check_mesh_for_writing(const std::filesystem::path& file, const HexMesh& mesh) {
  const auto fail = [&](const std::string& what) {
    throw Error(fmt::format("{}: cannot write: {}", file.string(), what));
  };
  const std::size_t nv = mesh.points.size();
  if (!mesh.blocks.empty() && mesh.blocks.size() != mesh.hexes.size())
    fail(fmt::format("the mesh has {} block ids for {} hexes", mesh.blocks.size(), mesh.hexes.size()));
  if (!mesh.fixed.empty() && mesh.fixed.size() != nv)
    fail(fmt::format("the mesh has {} fixed flags for {} vertices", mesh.fixed.size(), nv));
  for (std::size_t v = 0; v < nv; ++v)
    if (!mesh.points[v].allFinite()) fail(fmt::format("vertex {} has a non-finite coordinate", v));
  for (std::size_t h = 0; h < mesh.hexes.size(); ++h)
    for (const Index id : mesh.hexes[h])
      if (id < 0 || static_cast<std::size_t>(id) >= nv)
        fail(fmt::format("hex {} has vertex id {} out of range [0, {})", h, id, nv));
  for (const FaceSet& fs : mesh.face_sets) {
    if (!is_identifier(fs.name)) fail(fmt::format("face set name '{}' is not letters, digits and '_' starting with a letter", fs.name));
    for (const auto& [h, f] : fs.faces)
      if (h < 0 || h >= mesh.num_hexes() || f < 0 || f > 5)
        fail(fmt::format("face set {} has face ({}, {}) out of range", fs.name, h, f));
  }
}

void TextOut::flush() {
  out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  buffer_.clear();
}

void BigEndianOut::flush() {
  out_.write(reinterpret_cast<const char*>(buffer_.data()), static_cast<std::streamsize>(buffer_.size()));
  buffer_.clear();
}

}  // namespace isohex::io
