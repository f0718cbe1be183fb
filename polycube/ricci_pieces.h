// Stage 3 on a whole sliced mesh (§3.3): every piece extracted, its uniform flat metric computed
// and laid out as a circle domain, the pieces spread over threads.
#pragma once

#include "polycube/circle_domain.h"
#include "polycube/flat_metric.h"
#include "polycube/piece_mesh.h"
#include "polycube/slice.h"

#include <vector>

namespace polycube {

struct RicciPiecesOptions {
  FlatMetricOptions metric;
  // Worker threads; 0: one per hardware thread, at most one per piece.
  int threads = 0;
};

// One piece: its local mesh, its flat metric, its layout, and the seconds spent on the last two.
struct PieceDomain {
  PieceMesh piece;
  FlatMetric metric;
  CircleDomain domain;
  double seconds = 0;
};

// The pieces in SlicedMesh::pieces order.
//   seconds  wall-clock time of the whole call; threads: how many were used
struct RicciPieces {
  std::vector<PieceDomain> pieces;
  double seconds = 0;
  int threads = 1;
};

// Runs extract_piece, flat_metric and circle_domain on every piece, largest pieces first, on
// `threads` threads. Throws what those throw (the error of the lowest-numbered failing piece,
// its message prefixed with "piece <i>: ").
RicciPieces ricci_pieces(const SlicedMesh& sliced, const RicciPiecesOptions& options = {});

}  // namespace polycube
