// Union-find over 0..n-1 with path halving: components of faces, vertices, local fans.
#pragma once

#include <numeric>
#include <vector>

namespace polycube {

class DisjointSets {
 public:
  explicit DisjointSets(int n = 0) { reset(n); }

  // n singletons again.
  void reset(int n) {
    parent_.resize(n);
    std::iota(parent_.begin(), parent_.end(), 0);
  }

  // Representative of x's set.
  int find(int x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }

  // Merges the sets of a and b, b's representative staying the representative; returns false
  // when they were already one set.
  bool unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    parent_[a] = b;
    return true;
  }

  int size() const { return static_cast<int>(parent_.size()); }

 private:
  std::vector<int> parent_;
};

}  // namespace polycube
