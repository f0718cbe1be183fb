#include "polycube/ricci_pieces.h"

#include "polycube/errors.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <numeric>
#include <string>
#include <thread>
#include <vector>

namespace polycube {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

}  // namespace

RicciPieces ricci_pieces(const SlicedMesh& sliced, const RicciPiecesOptions& options) {
  const auto start = Clock::now();
  const int n = static_cast<int>(sliced.pieces.size());
  RicciPieces out;
  out.pieces.resize(n);
  // Largest first, so the last piece a thread picks up is a small one.
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return sliced.pieces[a].faces.size() > sliced.pieces[b].faces.size();
  });
  std::vector<std::exception_ptr> errors(n);
  std::atomic<int> next{0};
  auto work = [&]() {
    for (int k = next++; k < n; k = next++) {
      const int i = order[k];
      try {
        PieceDomain& d = out.pieces[i];
        d.piece = extract_piece(sliced, i);
        const auto t = Clock::now();
        d.metric = flat_metric(d.piece.mesh, d.piece.loops, options.metric);
        d.domain = circle_domain(d.piece.mesh, d.metric);
        d.seconds = seconds_since(t);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  int threads = options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::clamp(threads, 1, std::max(1, n));
  out.threads = threads;
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();

  for (int i = 0; i < n; ++i) {
    if (!errors[i]) continue;
    const std::string prefix = "piece " + std::to_string(i) + ": ";
    try {
      std::rethrow_exception(errors[i]);
    } catch (const MeshError& e) {
      throw MeshError(prefix + e.what());
    } catch (const AlgorithmError& e) {
      throw AlgorithmError(prefix + e.what());
    }
  }
  out.seconds = seconds_since(start);
  return out;
}

}  // namespace polycube
