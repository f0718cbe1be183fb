#include "cli/stage_json.h"

namespace polycube::cli {

nlohmann::json topology_json(const TopologyResult& topology) {
  nlohmann::json j;
  const CriticalPoints& critical = topology.critical;
  j["critical_points"] = {{"minima", critical.minima.size()},
                          {"maxima", critical.maxima.size()},
                          {"saddles", critical.saddle_count()},
                          {"cancelled_pairs", critical.cancelled_pairs}};
  j["cutting_planes"] = topology.planes_z;
  j["cutting_planes_normalised"] = topology.planes_normalised;
  j["planes_initial"] = topology.initial_planes.z.size();
  j["planes_girth"] = topology.initial_planes.girth_planes;
  j["planes_added_for_genus"] = topology.planes_added_for_genus;
  j["split_saddles"] = topology.split_saddles;
  j["nudged_planes"] = topology.sliced.nudged_planes;
  nlohmann::json pieces = nlohmann::json::array();
  int max_genus = 0;
  for (const Piece& piece : topology.sliced.pieces) {
    pieces.push_back({{"genus", piece.genus},
                      {"boundaries", piece.boundary_loops.size()},
                      {"triangles", piece.faces.size()},
                      {"euler", piece.euler},
                      {"plane_below", piece.plane_below},
                      {"plane_above", piece.plane_above}});
    max_genus = std::max(max_genus, piece.genus);
  }
  j["pieces"] = pieces;
  j["piece_count"] = topology.sliced.pieces.size();
  j["max_piece_genus"] = max_genus;
  j["intrinsic_flips"] = topology.harmonic.intrinsic_flips;
  j["harmonic_factorisation"] = topology.harmonic.supernodal ? "supernodal (CHOLMOD)" : "simplicial (Eigen)";
  j["harmonic_residual"] = topology.harmonic.residual;
  j["seconds"] = {{"harmonic", topology.seconds_harmonic},
                  {"critical_points", topology.seconds_critical},
                  {"planes", topology.seconds_planes},
                  {"slicing", topology.seconds_slicing},
                  {"total", topology.seconds_total}};
  return j;
}

}  // namespace polycube::cli
