#pragma once
/// \file union_find.hpp
/// \brief Disjoint sets with path halving and union by size (used by validation, sheets and component counts).

#include "isohex/mesh/hex_mesh.hpp"

#include <numeric>
#include <utility>
#include <vector>

namespace isohex::detail {

/// Disjoint-set forest over 0..n-1.
class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n), size_(n, 1) { std::iota(parent_.begin(), parent_.end(), 0); }
  /// The representative of `x`'s set.
  Index find(Index x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];  // path halving keeps the trees flat without recursion
      x = parent_[x];
    }
    return x;
  }
  /// Merges the sets of `a` and `b`; true if they were different.
  bool unite(Index a, Index b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
    return true;
  }

 private:
  std::vector<Index> parent_;
  std::vector<Index> size_;
};

}  // namespace isohex::detail
