// Which finished try `polycube quad` writes (cli/quad.cpp). Header-only so the rule is tested
// apart from the long runs that reach it (tests/cli/quad_choice_test.cpp).
#pragma once

#include <cstddef>
#include <tuple>
#include <vector>

namespace polycube {

// A try's rank, smaller first: flipped + degenerate quads, beyond the warning's Hausdorff
// distance (0 / 1), more quads than asked allows (0 / 1), the distance (% of the diagonal).
using QuadTryRank = std::tuple<int, int, int, double>;

// Valid quads before few quads. `kept` is the try the search kept, the best of those within the
// quads asked allows (and the first try, never capped); `ranks` holds every finished try's rank.
// When the kept try still has flipped or degenerate quads and another has fewer, the best-ranked
// of those with the fewest is returned, however many quads it made; else `kept`.
inline size_t prefer_fewer_bad_quads(const std::vector<QuadTryRank>& ranks, size_t kept) {
  size_t best = kept;
  for (size_t i = 0; i < ranks.size(); ++i)
    if (ranks[i] < ranks[best]) best = i;
  return std::get<0>(ranks[best]) < std::get<0>(ranks[kept]) ? best : kept;
}

}  // namespace polycube
