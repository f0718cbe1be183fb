// JSON views of the engine's stage results, shared by `inspect --topology` and `map`'s report.
#pragma once

#include "polycube/topology.h"

#include <nlohmann/json.hpp>

namespace polycube::cli {

// critical_points {minima, maxima, saddles}, cutting_planes (input coordinates), pieces
// [{genus, boundaries, triangles, plane_below, plane_above}], counts and seconds.
nlohmann::json topology_json(const TopologyResult& topology);

}  // namespace polycube::cli
