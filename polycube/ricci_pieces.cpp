#include "polycube/ricci_pieces.h"

#include "polycube/parallel.h"

#include <algorithm>
#include <chrono>
#include <numeric>
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
  out.threads = parallel_for_each(order, options.threads, "piece", [&](int i) {
    PieceDomain& d = out.pieces[i];
    d.piece = extract_piece(sliced, i);
    const auto t = Clock::now();
    d.metric = flat_metric(d.piece.mesh, d.piece.loops, options.metric);
    d.domain = circle_domain(d.piece.mesh, d.metric);
    d.seconds = seconds_since(t);
  });
  out.seconds = seconds_since(start);
  return out;
}

}  // namespace polycube
