#pragma once
// Disjoint sets over 0..n-1 with path halving; a union keeps the smaller index as the root (deterministic roots).
// Used to group corners into vertices (model check, the network repairs) and shared control points (G2 solve).
#include <algorithm>
#include <numeric>
#include <vector>

namespace seam {

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(static_cast<size_t>(n)) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[static_cast<size_t>(x)] != x) {
      parent[static_cast<size_t>(x)] = parent[static_cast<size_t>(parent[static_cast<size_t>(x)])];
      x = parent[static_cast<size_t>(x)];
    }
    return x;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
  }
};

}  // namespace seam
