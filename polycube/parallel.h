// Work over independent items (pieces, contours) spread over threads, with the errors of the
// items reported deterministically (the lowest failing item's, prefixed with its name).
#pragma once

#include "polycube/errors.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <numeric>
#include <string>
#include <thread>
#include <vector>

namespace polycube {

// The process-wide most threads one parallel step may use (0: no limit); the CLI's --threads.
// Steps run inside another step's items (the orientation candidates' maps, each mapping its
// pieces) can together use this many per outer thread.
inline std::atomic<int>& thread_limit() {
  static std::atomic<int> limit{0};
  return limit;
}

// How many threads a request for `threads` gets (0: one per hardware thread), within the limit.
inline int threads_for(int threads) {
  if (threads <= 0) threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const int limit = thread_limit().load();
  return limit > 0 ? std::min(threads, limit) : threads;
}

// Calls work(i) for every i in `order` (largest items first is best), on `threads` threads (0:
// one per hardware thread; see threads_for), at most one thread per item. If items throw,
// rethrows the error of the smallest such i, a MeshError or AlgorithmError with its message
// prefixed by "<what> <i>: ". Returns the number of threads used.
template <class Work>
int parallel_for_each(const std::vector<int>& order, int threads, const std::string& what, Work&& work) {
  const int n = static_cast<int>(order.size());
  int max_index = -1;
  for (int i : order) max_index = std::max(max_index, i);
  std::vector<std::exception_ptr> errors(max_index + 1);
  std::atomic<int> next{0};
  auto run = [&]() {
    for (int k = next++; k < n; k = next++) {
      try {
        work(order[k]);
      } catch (...) {
        errors[order[k]] = std::current_exception();
      }
    }
  };
  threads = std::clamp(threads_for(threads), 1, std::max(1, n));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(run);
  run();
  for (std::thread& t : pool) t.join();
  for (size_t i = 0; i < errors.size(); ++i) {
    if (!errors[i]) continue;
    const std::string prefix = what + " " + std::to_string(i) + ": ";
    try {
      std::rethrow_exception(errors[i]);
    } catch (const MeshError& e) {
      throw MeshError(prefix + e.what());
    } catch (const AlgorithmError& e) {
      throw AlgorithmError(prefix + e.what());
    }
  }
  return threads;
}

// Runs work(i) for i in [0, n) on `threads` threads (0: one per hardware thread), in 64
// contiguous blocks taken in turn (neighbouring items, often near in space, stay on one thread:
// with interleaved blocks, the parallel audit took gargoyle's orientation search from 3.1 to
// 3.75 s, median of 4 runs); errors as parallel_for_each's (prefixed "block <k>: ").
template <class Work>
void parallel_range(int n, int threads, Work&& work) {
  if (n <= 0) return;
  constexpr int kBlocks = 64;
  const int count = std::min(kBlocks, n);
  std::vector<int> blocks(count);
  std::iota(blocks.begin(), blocks.end(), 0);
  parallel_for_each(blocks, threads, "block", [&](int block) {
    const int begin = static_cast<int>(static_cast<long long>(n) * block / count);
    const int end = static_cast<int>(static_cast<long long>(n) * (block + 1) / count);
    for (int i = begin; i < end; ++i) work(i);
  });
}

}  // namespace polycube
