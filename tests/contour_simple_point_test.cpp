// Simple points for marching cubes' (6, 18) topology, checked against global component
// counts on blocks of 5x5x5 points (outside border) before and after the flip.
#include "isohex/contour/simple_point.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <vector>

namespace {

using isohex::contour::is_simple_6_18;
using isohex::contour::Neighbourhood;

constexpr int N = 5;
using Block = std::array<bool, N * N * N>;
int at(int x, int y, int z) { return x + N * (y + N * z); }

// Components of the points with flag `value` (6-adjacency for inside, 18 for outside).
int count_components(const Block& b, bool value) {
  const int reach = value ? 1 : 2;
  std::vector<int> label(b.size(), -1);
  int n = 0;
  for (int s = 0; s < N * N * N; ++s) {
    if (b[static_cast<std::size_t>(s)] != value || label[static_cast<std::size_t>(s)] >= 0) continue;
    std::vector<int> stack{s};
    label[static_cast<std::size_t>(s)] = n;
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      const int px = p % N, py = p / N % N, pz = p / (N * N);
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int d = std::abs(dx) + std::abs(dy) + std::abs(dz);
            if (d == 0 || d > reach) continue;
            const int x = px + dx, y = py + dy, z = pz + dz;
            if (x < 0 || y < 0 || z < 0 || x >= N || y >= N || z >= N) continue;
            const auto q = static_cast<std::size_t>(at(x, y, z));
            if (b[q] == value && label[q] < 0) {
              label[q] = n;
              stack.push_back(static_cast<int>(q));
            }
          }
    }
    ++n;
  }
  return n;
}

Neighbourhood around_centre(const Block& b) {
  Neighbourhood nb{};
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 3; ++x) nb[static_cast<std::size_t>(x + 3 * y + 9 * z)] = b[static_cast<std::size_t>(at(x + 1, y + 1, z + 1))];
  return nb;
}

Block from_neighbourhood(const Neighbourhood& nb) {
  Block b{};
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 3; ++x) b[static_cast<std::size_t>(at(x + 1, y + 1, z + 1))] = nb[static_cast<std::size_t>(x + 3 * y + 9 * z)];
  return b;
}

Neighbourhood from_string(const char* s) {  // 27 chars, '#' inside, x fastest
  Neighbourhood nb{};
  for (int p = 0; p < 27; ++p) nb[static_cast<std::size_t>(p)] = s[p] == '#';
  return nb;
}

}  // namespace

TEST(SimplePoint, HandCases) {
  // An isolated point: removing it deletes a component.
  EXPECT_FALSE(is_simple_6_18(from_string(".............#.............")));
  // Nothing around: adding the point creates a component.
  EXPECT_FALSE(is_simple_6_18(from_string("...........................")));
  // A point on a flat face (the lower half-block inside): simple.
  EXPECT_TRUE(is_simple_6_18(from_string("##################.........")));
  // The end of a straight rod: simple; the middle of a rod: not (it cuts the rod).
  EXPECT_TRUE(is_simple_6_18(from_string("....#........#.............")));
  EXPECT_FALSE(is_simple_6_18(from_string("....#........#........#....")));
  // A point enclosed by inside points on all 26 sides: filling a one-point cavity is not simple.
  Neighbourhood full{};
  full.fill(true);
  full[13] = false;
  EXPECT_FALSE(is_simple_6_18(full));
  // A ring of 8 points around the centre in the z = 1 plane: the centre closes a tunnel.
  EXPECT_FALSE(is_simple_6_18(from_string(".........####.####.........")));
}

// Simplicity implies the same number of inside (6-adjacency) and outside (18-adjacency)
// components after the flip; and for most blocks the converse shows up as a change.
TEST(SimplePoint, KeepsComponentCounts) {
  std::mt19937_64 rng(12345);
  int simple = 0, checked = 0;
  for (int trial = 0; trial < 40000; ++trial) {
    const double density = 0.15 + 0.7 * static_cast<double>(trial % 8) / 7.0;
    std::bernoulli_distribution in(density);
    Neighbourhood nb{};
    for (auto&& v : nb) v = in(rng);
    Block b = from_neighbourhood(nb);
    const int in_before = count_components(b, true), out_before = count_components(b, false);
    const bool s = is_simple_6_18(around_centre(b));
    b[static_cast<std::size_t>(at(2, 2, 2))] = !b[static_cast<std::size_t>(at(2, 2, 2))];
    EXPECT_EQ(s, is_simple_6_18(around_centre(b))) << "simplicity must not depend on the point's own flag";
    if (s) {
      ++simple;
      ASSERT_EQ(count_components(b, true), in_before) << "trial " << trial;
      ASSERT_EQ(count_components(b, false), out_before) << "trial " << trial;
    }
    ++checked;
  }
  // Neither always nor never simple on random blocks.
  EXPECT_GT(simple, checked / 20);
  EXPECT_LT(simple, checked - checked / 20);
}
