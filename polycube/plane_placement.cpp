#include "polycube/plane_placement.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace polycube {

double place_plane(const std::vector<double>& sorted_heights, double target, double lo, double hi, double window) {
  if (!(lo < hi)) throw std::invalid_argument("place_plane: empty interval");
  target = std::clamp(target, lo, hi);
  const double from = std::max(lo, target - window), to = std::min(hi, target + window);
  // Gaps are between consecutive elements of {lo, heights in (lo, hi), hi}; only the parts of
  // them inside [from, to] are candidates.
  auto first = std::upper_bound(sorted_heights.begin(), sorted_heights.end(), lo);
  auto last = std::lower_bound(sorted_heights.begin(), sorted_heights.end(), hi);
  // Start with the gap containing `from`.
  auto it = std::upper_bound(first, last, from);
  double below = it == first ? lo : *(it - 1);
  double best = target, best_clearance = -1, best_offset = 0;
  while (true) {
    const double above = it == last ? hi : *it;
    if (above > below) {
      // Point of [from, to] nearest the middle of (below, above).
      const double p = std::clamp(0.5 * (below + above), std::max(below, from), std::min(above, to));
      const double clearance = std::min(p - below, above - p);
      const double offset = std::abs(p - target);
      if (p > below && p < above &&
          (clearance > best_clearance || (clearance == best_clearance && offset < best_offset))) {
        best = p;
        best_clearance = clearance;
        best_offset = offset;
      }
    }
    if (it == last || above >= to) break;
    below = above;
    ++it;
  }
  return best;
}

}  // namespace polycube
