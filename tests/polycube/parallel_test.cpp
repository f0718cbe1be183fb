// parallel_for_each / parallel_range: every item once, on any number of threads, and the error
// of the lowest failing item.
#include "polycube/errors.h"
#include "polycube/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <thread>
#include <vector>

namespace polycube {
namespace {

TEST(Parallel, RangeVisitsEveryIndexOnceInContiguousBlocks) {
  for (const int n : {1, 7, 63, 64, 65, 1000, 4099})
    for (const int threads : {0, 1, 3, 8}) {
      std::vector<std::atomic<int>> visits(n);
      std::vector<std::thread::id> worker(n);
      parallel_range(n, threads, [&](int i) {
        ++visits[i];
        worker[i] = std::this_thread::get_id();
      });
      for (int i = 0; i < n; ++i) ASSERT_EQ(visits[i].load(), 1) << "n " << n << ", threads " << threads << ", index " << i;
      // Blocks are contiguous: with at most 64 blocks, items change hands at most 63 times.
      int changes = 0;
      for (int i = 1; i < n; ++i) changes += worker[i] != worker[i - 1];
      EXPECT_LE(changes, 63) << "n " << n << ", threads " << threads;
    }
  int calls = 0;
  parallel_range(0, 4, [&](int) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(Parallel, ErrorOfTheLowestFailingItemWithItsName) {
  const std::vector<int> order = {5, 3, 9, 1, 7};
  try {
    parallel_for_each(order, 3, "piece", [](int i) {
      if (i == 3 || i == 7) throw AlgorithmError("broke at " + std::to_string(i));
    });
    FAIL() << "no error";
  } catch (const AlgorithmError& e) {
    EXPECT_EQ(std::string(e.what()), "piece 3: broke at 3");
  }
}

}  // namespace
}  // namespace polycube
