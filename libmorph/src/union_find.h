// Private: disjoint sets over 0..n-1, each named by its lowest member (so the names, and
// what callers number by them, do not depend on the order of the unions).
#pragma once

#include <algorithm>
#include <numeric>
#include <vector>

namespace morph::detail {

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  /// The name of x's set (path halving).
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  /// Joins the sets of a and b.
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace morph::detail
