// The rule that picks the try `polycube quad` writes (cli/quad_choice.h).
#include "cli/quad_choice.h"

#include <gtest/gtest.h>

#include <vector>

namespace polycube {
namespace {

// gyroid's tries (bench/unseen.md): the uncapped first try kept 1 flipped quad (0.666 %); the
// capped tries within the quads asked allows did no better; the thin-parts try had none but
// 36 588 quads, more than asked allows. The valid one is written.
TEST(QuadChoice, AValidTryOverTheSizeBeatsAKeptTryWithAFlippedQuad) {
  const std::vector<QuadTryRank> ranks = {{1, 1, 1, 0.666}, {3, 1, 0, 0.9}, {0, 1, 1, 0.804}, {0, 1, 1, 0.95}};
  EXPECT_EQ(prefer_fewer_bad_quads(ranks, 0), 2u);
}

// Among tries with fewer bad quads, the fewest win, then the rank (distance last).
TEST(QuadChoice, TheFewestBadQuadsThenTheRank) {
  const std::vector<QuadTryRank> ranks = {{4, 1, 0, 0.6}, {2, 0, 1, 0.3}, {1, 1, 1, 2.0}, {1, 1, 1, 1.5}, {1, 1, 1, 1.7}};
  EXPECT_EQ(prefer_fewer_bad_quads(ranks, 0), 3u);
}

// A kept try with no bad quad stays, however well another try ranks: the size cap then holds.
TEST(QuadChoice, AValidKeptTryStays) {
  const std::vector<QuadTryRank> ranks = {{0, 1, 0, 0.9}, {0, 0, 1, 0.2}, {0, 0, 0, 0.1}};
  EXPECT_EQ(prefer_fewer_bad_quads(ranks, 0), 0u);
  EXPECT_EQ(prefer_fewer_bad_quads(ranks, 2), 2u);
}

// Tries with as many bad quads as the kept one do not replace it, even when nearer the model.
TEST(QuadChoice, AsManyBadQuadsIsNoReason) {
  const std::vector<QuadTryRank> ranks = {{2, 1, 0, 0.9}, {2, 0, 1, 0.2}, {3, 0, 0, 0.1}};
  EXPECT_EQ(prefer_fewer_bad_quads(ranks, 0), 0u);
  EXPECT_EQ(prefer_fewer_bad_quads({{1, 0, 0, 0.1}}, 0), 0u);
}

}  // namespace
}  // namespace polycube
