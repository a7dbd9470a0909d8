// Hex selections from CLI specifications: all, block:ID, region:EXPR, ids:FILE.
#include "isohex/volume/hex_selection.hpp"

#include "isohex/error.hpp"
#include "isohex/volume/implicit.hpp"

#include <fmt/format.h>

#include <charconv>
#include <fstream>

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

std::vector<std::uint8_t> from_ids_file(const HexMesh& mesh, const std::string& file, std::string_view context) {
  return read_id_list(file, mesh.hexes.size(), "hex", context);
}

}  // namespace

std::vector<std::uint8_t> read_id_list(const std::string& file, std::size_t count, std::string_view noun,
                                       std::string_view context) {
  std::ifstream in(file);
  if (!in) throw Error(fmt::format("{}: cannot open ids file '{}'", context, file));
  std::vector<std::uint8_t> set(count, 0);
  std::string line;
  for (long line_no = 1; std::getline(in, line); ++line_no) {
    const std::string_view t = trim(line);
    if (t.empty() || t.front() == '#') continue;
    long long id = 0;
    if (!parse_int(t, id))
      throw Error(fmt::format("{}: {}, line {}: '{}' is not a {} id", context, file, line_no, t, noun));
    if (id < 0 || static_cast<unsigned long long>(id) >= count)
      throw Error(fmt::format("{}: {}, line {}: {} id {} is out of range [0, {})", context, file, line_no, noun, id,
                              count));
    set[static_cast<std::size_t>(id)] = 1;
  }
  return set;
}

std::vector<std::uint8_t> select_hexes(const HexMesh& mesh, const std::string& spec, std::string_view context,
                                       std::string_view all_keyword) {
  const auto colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string arg = colon == std::string::npos ? std::string() : spec.substr(colon + 1);
  if (kind == all_keyword && colon == std::string::npos) return std::vector<std::uint8_t>(mesh.hexes.size(), 1);
  if (kind == "block" && colon != std::string::npos) {
    long long block = 0;
    if (!parse_int(trim(arg), block)) throw Error(fmt::format("{}: '{}' is not a block id", context, arg));
    std::vector<std::uint8_t> set(mesh.hexes.size(), 0);
    for (Index h = 0; h < mesh.num_hexes(); ++h) set[h] = mesh.block(h) == block;
    return set;
  }
  if (kind == "region" && colon != std::string::npos) {
    const Shape shape = parse_shape(arg);
    std::vector<std::uint8_t> set(mesh.hexes.size(), 0);
    for (Index h = 0; h < mesh.num_hexes(); ++h) set[h] = evaluate(shape, mesh.centroid(h)) < 0;
    return set;
  }
  if (kind == "ids" && colon != std::string::npos) return from_ids_file(mesh, arg, context);
  throw Error(fmt::format("{}: unknown specification '{}' (expected {}, block:ID, region:EXPR or ids:FILE)", context,
                          spec, all_keyword));
}

}  // namespace isohex
