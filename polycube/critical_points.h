// Critical points of a piecewise-linear function on a closed triangulated surface (§3.1), by
// piecewise-linear Morse theory on the vertex links.
#pragma once

#include "polycube/intrinsic_delaunay.h"

#include <Eigen/Core>

#include <vector>

namespace polycube {

struct CriticalPointOptions {
  // Cancel every extremum other than the kept ones against the saddle at which its component
  // joins another (0-dimensional persistence, elder rule). For a harmonic function the maximum
  // principle allows no interior extrema, so any that appear are rounding in flat regions
  // (e.g. at the tip of a long branch) and are removed with a saddle each; the Euler relation
  // #min - #saddles + #max = χ stays exact. Off for functions that have genuine extrema.
  bool cancel_extra_extrema = false;
  // The minimum and maximum that survive cancellation (-1: the global ones).
  int keep_minimum = -1;
  int keep_maximum = -1;
  // Values compared where f is equal, before the vertex id (#V entries, or null). The height z
  // suits the harmonic function: where f is flat to the last bit (far out on a thin branch),
  // z orders neighbours as the surface does instead of by arbitrary ids, so fewer spurious
  // extrema appear in the first place.
  const Eigen::VectorXd* tie_break = nullptr;
};

// Critical vertices, each list ascending by vertex id.
//   minima, maxima         vertices whose link is entirely above / below them
//   saddles                vertices whose link changes sign 2(m+1) times, m >= 1
//   saddle_multiplicity    m for each saddle (2 for a monkey saddle)
//   raw_*                  the same counts before cancellation
//   cancelled_pairs        extremum-saddle pairs removed by cancellation
//   unmatched_cancellations  cancellations whose saddle had no multiplicity left (0 in theory;
//                          reported so that tests can check it)
struct CriticalPoints {
  std::vector<int> minima, maxima;
  std::vector<int> saddles;
  std::vector<int> saddle_multiplicity;
  int raw_minima = 0;
  int raw_maxima = 0;
  int raw_saddle_count = 0;
  int cancelled_pairs = 0;
  int unmatched_cancellations = 0;

  // Saddles counted with multiplicity; 2g on a genus-g surface when there is one minimum and
  // one maximum.
  int saddle_count() const;
};

// Classifies every vertex by the sign changes of f(u) - f(v) around its link in cyclic order.
// Equal values are ordered by options.tie_break, then by vertex id (simulation of simplicity:
// compare (f, tie_break, id) lexicographically), so every vertex is either regular or critical
// and #minima - saddle_count() + #maxima = χ holds exactly.
//   triangulation  a closed oriented triangulation given by faces and face adjacency: the
//                  intrinsic Delaunay one f was solved on (HarmonicFunction::intrinsic), or the
//                  mesh's own (intrinsic_delaunay with max_flips_per_edge = 0). Several edges
//                  may join two vertices; no edge may join a vertex to itself.
//   f              #V function values
// Throws AlgorithmError for non-finite values, MeshError for a vertex whose faces do not form
// one fan.
CriticalPoints critical_points(const IntrinsicTriangulation& triangulation, const Eigen::VectorXd& f,
                               const CriticalPointOptions& options = {});

}  // namespace polycube
