#pragma once
// Helpers for the legacy VTK / MEDIT / Abaqus reader tests: meshes with awkward values,
// exact mesh comparison, error expectations and the truncation sweep.

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/mesh_io.hpp"
#include "test_support.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace isohex::test {

namespace fs = std::filesystem;

/// `text` with the first `from` replaced by `to` (a test failure if `from` is absent).
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

inline void write_text(const fs::path& file, const std::string& bytes) {
  fs::remove(file);  // much faster than truncating in place on some file systems
  std::ofstream out(file, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << file;
}

/// A 3x2x2 grid whose coordinates include values that only exact output survives.
inline HexMesh awkward_mesh(bool with_blocks, bool with_fixed) {
  HexMesh m = grid_mesh(3, 2, 2);
  const double awkward[] = {1.0 / 3.0,
                            1e-300,
                            -0.0,
                            1e300,
                            std::numeric_limits<double>::denorm_min(),
                            -std::numeric_limits<double>::max(),
                            0.1,
                            M_PI,
                            -2.5e-17,
                            123456789.123456789};
  // Every other coordinate is replaced, so plain grid values stay in between.
  for (std::size_t v = 0; v < m.points.size(); ++v)
    for (int c = 0; c < 3; ++c)
      if ((v + static_cast<std::size_t>(c)) % 2 == 0)
        m.points[v][c] = awkward[(3 * v + static_cast<std::size_t>(c)) % std::size(awkward)];
  if (with_blocks) {
    m.blocks.resize(m.hexes.size());
    for (std::size_t h = 0; h < m.blocks.size(); ++h)
      m.blocks[h] = static_cast<Index>((h * 5) % 3 == 0 ? -4 : h % 4 + 1);
    m.blocks.back() = std::numeric_limits<Index>::max();
  }
  if (with_fixed) {
    m.fixed.assign(m.points.size(), 0);
    for (std::size_t v = 0; v < m.fixed.size(); v += 3) m.fixed[v] = 1;
  }
  return m;
}

inline bool fixed_flag(const HexMesh& m, std::size_t v) { return !m.fixed.empty() && m.fixed[v] != 0; }

/// Same coordinates bit for bit (so -0.0 differs from 0.0), connectivity, blocks and fixed
/// flags (an empty `blocks` reads as block 0 everywhere, an empty `fixed` as none fixed).
inline void expect_same_mesh(const HexMesh& expected, const HexMesh& actual) {
  ASSERT_EQ(expected.points.size(), actual.points.size());
  ASSERT_EQ(expected.hexes.size(), actual.hexes.size());
  for (std::size_t v = 0; v < expected.points.size(); ++v)
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(std::bit_cast<std::uint64_t>(expected.points[v][c]), std::bit_cast<std::uint64_t>(actual.points[v][c]))
          << "vertex " << v << " coordinate " << c << ": " << expected.points[v][c] << " vs " << actual.points[v][c];
  for (std::size_t h = 0; h < expected.hexes.size(); ++h) {
    ASSERT_EQ(expected.hexes[h], actual.hexes[h]) << "hex " << h;
    ASSERT_EQ(expected.block(static_cast<Index>(h)), actual.block(static_cast<Index>(h))) << "hex " << h;
  }
  for (std::size_t v = 0; v < expected.points.size(); ++v)
    ASSERT_EQ(fixed_flag(expected, v), fixed_flag(actual, v)) << "vertex " << v;
}

/// Reads `file` expecting isohex::Error; returns its message after checking that it names
/// the file and contains every one of `fragments`.
inline std::string expect_read_error(const fs::path& file, const std::vector<std::string>& fragments,
                                     const io::ReadOptions& options = {}) {
  try {
    io::read_mesh(file, options);
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    for (const std::string& f : fragments)
      EXPECT_NE(message.find(f), std::string::npos) << "'" << f << "' not in: " << message;
    return message;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an isohex::Error: " << e.what();
    return {};
  }
  ADD_FAILURE() << file << " was read without error";
  return {};
}

/// Writes `text` to `dir/name` and expects reading it to fail as expect_read_error says.
inline std::string expect_text_error(const fs::path& dir, const std::string& name, const std::string& text,
                                     const std::vector<std::string>& fragments, const io::ReadOptions& options = {}) {
  const fs::path file = dir / name;
  write_text(file, text);
  return expect_read_error(file, fragments, options);
}

/// Reads every prefix of `full` whose length `lengths` yields (as file `dir/name`). Each read
/// must either throw isohex::Error naming the file and a place ("line " or "byte "), or
/// succeed; `may_succeed(length)` says whether success is acceptable at that length, and a
/// successful read must give no more vertices and hexes than `whole`.
inline void sweep_prefixes(const fs::path& dir, const std::string& name, const std::string& full,
                           const std::vector<std::size_t>& lengths, const HexMesh& whole,
                           const std::function<bool(std::size_t)>& may_succeed) {
  const fs::path file = dir / name;
  const bool failed_before = ::testing::Test::HasFailure();
  for (const std::size_t length : lengths) {
    write_text(file, full.substr(0, length));
    try {
      const HexMesh m = io::read_mesh(file);
      EXPECT_TRUE(may_succeed(length)) << "prefix of " << length << " of " << full.size() << " bytes was read: ..."
                                       << ::testing::PrintToString(full.substr(length > 48 ? length - 48 : 0, 48));
      EXPECT_LE(m.points.size(), whole.points.size());
      EXPECT_LE(m.hexes.size(), whole.hexes.size());
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind(file.string() + ": ", 0), 0u) << message;
      EXPECT_TRUE(message.find(": line ") != std::string::npos || message.find(": byte ") != std::string::npos)
          << message;
    }
    if (!failed_before && ::testing::Test::HasFailure()) {
      ADD_FAILURE() << "stopped at prefix length " << length;
      return;
    }
  }
}

/// 0, 1, ..., n - 1.
inline std::vector<std::size_t> all_lengths(std::size_t n) {
  std::vector<std::size_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = i;
  return v;
}

/// About `count` lengths spread over [0, n), plus the first and last 64.
inline std::vector<std::size_t> spread_lengths(std::size_t n, std::size_t count) {
  std::vector<std::size_t> v;
  for (std::size_t i = 0; i < n && i < 64; ++i) v.push_back(i);
  for (std::size_t i = 1; i < count; ++i) v.push_back(n * i / count);
  for (std::size_t i = n > 64 ? n - 64 : 0; i < n; ++i) v.push_back(i);
  return v;
}

/// The files of `dir` whose names start with '.' (atomic_file's temporaries).
inline std::vector<std::string> hidden_files(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().starts_with(".")) out.push_back(e.path().filename().string());
  return out;
}

}  // namespace isohex::test
