// Shrink sets from CLI specifications: boundary, block:ID, region:EXPR, ids:FILE.
#include "isohex/error.hpp"
#include "isohex/sheets/pillow.hpp"
#include "isohex/volume/implicit.hpp"

#include <fmt/format.h>

#include <charconv>
#include <fstream>
#include <string_view>

namespace isohex {

namespace {

/// Parses a whole string as a decimal integer (no sign for ids; blocks may be any Index).
bool parse_int(std::string_view s, long long& value) {
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  return ec == std::errc() && end == s.data() + s.size();
}

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

std::vector<std::uint8_t> from_ids_file(const HexMesh& mesh, const std::string& file) {
  std::ifstream in(file);
  if (!in) throw Error(fmt::format("shrink set: cannot open ids file '{}'", file));
  std::vector<std::uint8_t> set(mesh.hexes.size(), 0);
  std::string line;
  for (long line_no = 1; std::getline(in, line); ++line_no) {
    const std::string_view t = trim(line);
    if (t.empty() || t.front() == '#') continue;
    long long id = 0;
    if (!parse_int(t, id))
      throw Error(fmt::format("shrink set: {}, line {}: '{}' is not a hex id", file, line_no, t));
    if (id < 0 || id >= mesh.num_hexes())
      throw Error(fmt::format("shrink set: {}, line {}: hex id {} is out of range [0, {})", file, line_no, id,
                              mesh.num_hexes()));
    set[static_cast<std::size_t>(id)] = 1;
  }
  return set;
}

}  // namespace

std::vector<std::uint8_t> shrink_set_from_spec(const HexMesh& mesh, const std::string& spec) {
  const auto colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string arg = colon == std::string::npos ? std::string() : spec.substr(colon + 1);
  if (kind == "boundary" && colon == std::string::npos) return std::vector<std::uint8_t>(mesh.hexes.size(), 1);
  if (kind == "block" && colon != std::string::npos) {
    long long block = 0;
    if (!parse_int(trim(arg), block)) throw Error(fmt::format("shrink set: '{}' is not a block id", arg));
    std::vector<std::uint8_t> set(mesh.hexes.size(), 0);
    for (Index h = 0; h < mesh.num_hexes(); ++h) set[h] = mesh.block(h) == block;
    return set;
  }
  if (kind == "region" && colon != std::string::npos) {
    const Shape shape = parse_shape(arg);
    std::vector<std::uint8_t> set(mesh.hexes.size(), 0);
    for (Index h = 0; h < mesh.num_hexes(); ++h) {
      Vec3 c = Vec3::Zero();
      for (Index v : mesh.hexes[h]) c += mesh.points[v];
      set[h] = evaluate(shape, c / 8) < 0;
    }
    return set;
  }
  if (kind == "ids" && colon != std::string::npos) return from_ids_file(mesh, arg);
  throw Error(fmt::format("shrink set: unknown specification '{}' (expected boundary, block:ID, region:EXPR or ids:FILE)",
                          spec));
}

bool spec_includes_boundary(const std::string& spec) { return spec == "boundary" || spec.rfind("block:", 0) == 0; }

}  // namespace isohex
