// Where exactly to put a horizontal cutting plane: away from the heights of the mesh vertices,
// so that slicing never meets a vertex on a plane and creates no needle triangles near one.
#pragma once

#include <vector>

namespace polycube {

// Returns a height in the open interval (lo, hi), within `window` of `target` when that part of
// the interval is not empty, that is as far as possible from every vertex height and from lo
// and hi: the middle of the widest gap between consecutive distinct heights there (ties: the one
// nearest target). Never equal to a vertex height unless two heights are adjacent doubles with
// nothing in between, which slice_mesh then handles by nudging.
//   sorted_heights  z of all mesh vertices, ascending (duplicates allowed)
//   target          preferred height, lo < target < hi
//   lo, hi          heights the plane must stay strictly between
//   window          how far from target the plane may move (> 0)
// Throws std::invalid_argument unless lo < hi.
double place_plane(const std::vector<double>& sorted_heights, double target, double lo, double hi, double window);

}  // namespace polycube
