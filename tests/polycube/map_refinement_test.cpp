// refine_map_sampling / refine_vertex_map_sampling (issue 5): on test meshes whose coarse P
// samples the map badly, the refined P is the same polycube surface (closed, same genus, every
// triangle axis-aligned in its polycube face, corners unchanged, a conforming triangulation),
// every new vertex's image lies on the model, the P → M direction audits with no flipped
// triangle and its image area within 2 %, the M → P samples keep their positions, and the
// refinement is never worse than its input.
#include "polycube/map_refinement.h"

#include "polycube/map_audit.h"
#include "polycube/map_smoothing.h"
#include "polycube/polycube_build.h"
#include "polycube/polycube_map.h"
#include "polycube/topology.h"
#include "support/test_support.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace polycube {
namespace {

using namespace test;

using Pipeline = MappedModel;
const Pipeline& pipeline(const std::string& name) { return mapped_model(name); }

int bad(const MapDirectionAudit& a) { return a.flipped + a.degenerate; }

// The refined P is the unrefined polycube's surface, triangulated finer without T-junctions.
void expect_same_polycube(const Polycube& unrefined, const Polycube& refined, int genus) {
  const TriMesh& P0 = unrefined.mesh;
  const TriMesh& P = refined.mesh;
  const double diagonal = bounding_box(P0.V).diagonal();
  ASSERT_GE(P.num_vertices(), P0.num_vertices());
  // Old vertices keep their ids and positions; corners and polycube vertices are the same.
  EXPECT_EQ(P.V.topRows(P0.num_vertices()), P0.V);
  EXPECT_EQ(refined.corners, unrefined.corners);
  EXPECT_EQ(refined.vertices, unrefined.vertices);
  EXPECT_EQ(refined.faces.size(), unrefined.faces.size());
  // Closed, edge-manifold, consistently oriented: every directed edge once, with its reverse.
  std::map<std::pair<int, int>, int> directed;
  for (int f = 0; f < P.num_faces(); ++f)
    for (int i = 0; i < 3; ++i) ++directed[{P.F(f, i), P.F(f, (i + 1) % 3)}];
  int bad_edges = 0;
  for (const auto& [edge, count] : directed) bad_edges += count != 1 || directed.count({edge.second, edge.first}) == 0;
  EXPECT_EQ(bad_edges, 0);
  // Same genus (χ = V − E + F = 2 − 2g), so no vertex is isolated and nothing is duplicated.
  const int edges = static_cast<int>(directed.size()) / 2;
  EXPECT_EQ(P.num_vertices() - edges + P.num_faces(), 2 - 2 * genus);
  // Every triangle non-degenerate, its normal exactly along its polycube face's axis, outward,
  // and on that face's plane.
  ASSERT_EQ(refined.face_axis.size(), P.num_faces());
  ASSERT_EQ(refined.face_patch.size(), P.num_faces());
  int off_axis = 0, off_plane = 0;
  for (int f = 0; f < P.num_faces(); ++f) {
    const Eigen::Vector3d a = P.V.row(P.F(f, 0)), b = P.V.row(P.F(f, 1)), c = P.V.row(P.F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const int axis = std::abs(refined.face_axis[f]) - 1;
    const int sign = refined.face_axis[f] > 0 ? 1 : -1;
    const PolycubeFace& face = refined.faces[refined.face_patch[f]];
    EXPECT_EQ(face.axis, axis);
    off_axis += n[(axis + 1) % 3] != 0 || n[(axis + 2) % 3] != 0 || sign * n[axis] <= 0;
    off_plane += a[axis] != face.coordinate || b[axis] != face.coordinate || c[axis] != face.coordinate;
  }
  EXPECT_EQ(off_axis, 0);
  EXPECT_EQ(off_plane, 0);
  EXPECT_NEAR(surface_area(P), surface_area(P0), 1e-9 * surface_area(P0));
  // Polycube edges run through mesh edges, between the same ends.
  ASSERT_EQ(refined.edges.size(), unrefined.edges.size());
  int broken = 0;
  for (size_t e = 0; e < refined.edges.size(); ++e) {
    const auto& v = refined.edges[e].vertices;
    EXPECT_EQ(v.front(), unrefined.edges[e].vertices.front());
    EXPECT_EQ(v.back(), unrefined.edges[e].vertices.back());
    for (size_t k = 0; k + 1 < v.size(); ++k) broken += directed.count({v[k], v[k + 1]}) == 0;
  }
  EXPECT_EQ(broken, 0);
  EXPECT_GT(refined.spacing, 0);
  EXPECT_LE(refined.spacing, unrefined.spacing + 1e-12 * diagonal);
}

// The samples over the refined P say what they claim: images on the model, M → P positions
// unchanged and expressed in the refined triangles.
void expect_consistent_samples(const TriMesh& model, const Polycube& refined, const PolycubeMap& input, const PolycubeMap& out) {
  const TriMesh& P = refined.mesh;
  const double model_diagonal = bounding_box(model.V).diagonal(), diagonal = bounding_box(P.V).diagonal();
  ASSERT_EQ(out.polycube_on_model.size(), static_cast<size_t>(P.num_vertices()));
  ASSERT_EQ(out.polycube_on_model_xyz.rows(), P.num_vertices());
  for (int v = 0; v < P.num_vertices(); ++v) {
    ASSERT_GE(out.polycube_on_model[v].face, 0);
    ASSERT_LT(out.polycube_on_model[v].face, model.num_faces());
    EXPECT_LE((surface_position(model, out.polycube_on_model[v]) - out.polycube_on_model_xyz.row(v).transpose()).norm(), 1e-12 * model_diagonal);
  }
  EXPECT_EQ(out.model_on_polycube_xyz, input.model_on_polycube_xyz);
  ASSERT_EQ(out.model_on_polycube.size(), static_cast<size_t>(model.num_vertices()));
  double moved = 0;
  for (int w = 0; w < model.num_vertices(); ++w)
    moved = std::max(moved, (surface_position(P, out.model_on_polycube[w]) - out.model_on_polycube_xyz.row(w).transpose()).norm());
  EXPECT_LE(moved, 1e-9 * diagonal);
}

// Small test meshes whose P, built in the input frame, samples φ with flipped triangles.
class MapRefinementOnMeshes : public ::testing::TestWithParam<std::string> {};

TEST_P(MapRefinementOnMeshes, SamePolycubeNoFlipsAreaWithinTwoPercent) {
  const Pipeline& p = pipeline(GetParam());
  const Polycube& P0 = p.polycube.polycube;
  // The unrefined sampling has flipped triangles (else this test would prove nothing).
  const MapDirectionAudit input = audit_map_direction(P0.mesh, p.map.polycube_on_model_xyz, p.model);
  ASSERT_GT(bad(input), 0);

  const MapRefinementResult r = refine_map_sampling(p.model, p.polycube, p.map);
  ASSERT_TRUE(r.refined);
  EXPECT_EQ(bad(r.before), bad(input));
  EXPECT_NEAR(r.before.area_ratio, input.area_ratio, 1e-12);
  EXPECT_GT(r.rounds, 0);
  EXPECT_GT(r.bisections, 0);
  EXPECT_EQ(r.vertices_before, P0.mesh.num_vertices());
  EXPECT_EQ(r.vertices_after, r.polycube.mesh.num_vertices());
  EXPECT_EQ(r.vertices_after, r.vertices_before + r.bisections);
  expect_same_polycube(P0, r.polycube, p.polycube.genus);
  expect_consistent_samples(p.model, r.polycube, p.map, r.map);

  // Every new vertex is a point of the unrefined P, and its image is φ there.
  ASSERT_EQ(r.polycube_origin.size(), static_cast<size_t>(r.vertices_after));
  const double diagonal = bounding_box(P0.mesh.V).diagonal();
  for (int v = r.vertices_before; v < r.vertices_after; ++v) {
    EXPECT_LE((surface_position(P0.mesh, r.polycube_origin[v]) - r.polycube.mesh.V.row(v).transpose()).norm(), 1e-9 * diagonal);
    const SurfacePoint image = p.map.to_model(r.polycube_origin[v]);
    EXPECT_EQ(image.face, r.map.polycube_on_model[v].face);
  }
  // The independent audit of P → M: no flipped or degenerate triangle, images on M, the area.
  const MapDirectionAudit after = audit_map_direction(r.polycube.mesh, r.map.polycube_on_model_xyz, p.model);
  EXPECT_EQ(after.flipped, 0);
  EXPECT_EQ(after.degenerate, 0);
  EXPECT_LE(after.max_distance, 1e-3);
  EXPECT_NEAR(after.area_ratio, 1, 0.02);
  EXPECT_GT(std::abs(input.area_ratio - 1), std::abs(after.area_ratio - 1));
  // The result's own counts are the audit's.
  EXPECT_EQ(r.after.flipped, after.flipped);
  EXPECT_EQ(r.after.degenerate, after.degenerate);
  EXPECT_NEAR(r.after.area_ratio, after.area_ratio, 1e-12);
  EXPECT_TRUE(r.converged);
  // M → P judged against the refined P is no worse.
  EXPECT_LE(bad(r.model_to_polycube_after), bad(r.model_to_polycube_before));
}

INSTANTIATE_TEST_SUITE_P(Meshes, MapRefinementOnMeshes, ::testing::Values("sphere.off", "knot.off"),
                         [](const auto& info) { return test_name_of_file(info.param); });

// On meshes where φ's chords keep flipping at every scale, the refinement still never returns a
// sampling with more bad P → M triangles, nor more bad triangles of both directions together.
TEST(MapRefinement, NeverWorse) {
  for (const std::string name : {"torus_quad.off", "eight.off", "joint.off", "helmet.off"}) {
    SCOPED_TRACE(name);
    const Pipeline& p = pipeline(name);
    const MapRefinementResult r = refine_map_sampling(p.model, p.polycube, p.map);
    const MapDirectionAudit input = audit_map_direction(p.polycube.polycube.mesh, p.map.polycube_on_model_xyz, p.model);
    const MapDirectionAudit after = audit_map_direction(r.polycube.mesh, r.map.polycube_on_model_xyz, p.model);
    EXPECT_LE(bad(after), bad(input));
    if (r.refined) {
      const MapDirectionAudit m_input = audit_map_direction(p.model, p.map.model_on_polycube_xyz, p.polycube.polycube.mesh);
      const MapDirectionAudit m_after = audit_map_direction(p.model, r.map.model_on_polycube_xyz, r.polycube.mesh);
      EXPECT_TRUE(bad(m_after) <= bad(m_input) || bad(after) + bad(m_after) < bad(input) + bad(m_input));
      expect_same_polycube(p.polycube.polycube, r.polycube, p.polycube.genus);
      expect_consistent_samples(p.model, r.polycube, p.map, r.map);
    } else {
      EXPECT_EQ(r.polycube.mesh.V, p.polycube.polycube.mesh.V);
      EXPECT_EQ(r.polycube.mesh.F, p.polycube.polycube.mesh.F);
    }
  }
}

// The first refinement's sampling smoothed, as the vertex samples the second refinement takes.
PolycubeMap smoothed_samples(const TriMesh& model, const MapRefinementResult& first) {
  const MapSmoothingResult smoothed = smooth_map(model, first.polycube, first.map);
  PolycubeMap samples;
  samples.polycube_on_model = smoothed.polycube_on_model;
  samples.polycube_on_model_xyz = smoothed.polycube_on_model_xyz;
  samples.model_on_polycube = smoothed.model_on_polycube;
  samples.model_on_polycube_xyz = smoothed.model_on_polycube_xyz;
  return samples;
}

// After the smoothing, which moves images off the model's edges (chords lose area again), the
// second refinement samples the smoothed map: same surface, no new bad triangle, area closer.
TEST(MapRefinement, AfterSmoothingSamplesTheSmoothedMap) {
  const Pipeline& p = pipeline("sphere.off");
  const MapRefinementResult first = refine_map_sampling(p.model, p.polycube, p.map);
  const PolycubeMap samples = smoothed_samples(p.model, first);
  const MapDirectionAudit input = audit_map_direction(first.polycube.mesh, samples.polycube_on_model_xyz, p.model);
  const MapRefinementResult second = refine_vertex_map_sampling(p.model, first.polycube, p.polycube.planes_z, samples);
  expect_same_polycube(first.polycube, second.polycube, p.polycube.genus);
  expect_consistent_samples(p.model, second.polycube, samples, second.map);
  const MapDirectionAudit after = audit_map_direction(second.polycube.mesh, second.map.polycube_on_model_xyz, p.model);
  EXPECT_LE(bad(after), bad(input));
  EXPECT_LE(after.max_distance, 1e-3);
  EXPECT_LE(std::abs(after.area_ratio - 1), std::max(0.02, std::abs(input.area_ratio - 1)));
}

// The model faces whose closure holds an image point (its face, the faces round the edge or
// vertex it lies on).
std::vector<int> closure_faces(const TriMesh& model, const SurfacePoint& y) {
  std::vector<int> out;
  for (int f = 0; f < model.num_faces(); ++f) {
    int shared = 0;
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) shared += y.bary[k] > 1e-12 && model.F(f, i) == model.F(y.face, k);
    int nonzero = 0;
    for (int k = 0; k < 3; ++k) nonzero += y.bary[k] > 1e-12;
    if (shared == nonzero) out.push_back(f);
  }
  return out;
}

// On a model with sharp edges the smoothed map's chords cut across them (a tetrahedron's image
// area falls far short); the second refinement splits P's edges where their images cross a model
// edge, with the new images on that edge, so that the chords come to lie in the model's faces:
// the area is then within 2 % (0.87 with midpoint bisections alone).
TEST(MapRefinement, SplitsWhereImagesCrossSharpModelEdges) {
  const Pipeline& p = pipeline("tetrahedron.off");
  const MapRefinementResult first = refine_map_sampling(p.model, p.polycube, p.map);
  const PolycubeMap samples = smoothed_samples(p.model, first);
  const MapDirectionAudit input = audit_map_direction(first.polycube.mesh, samples.polycube_on_model_xyz, p.model);
  ASSERT_LT(input.area_ratio, 0.9);  // else this proves nothing

  const MapRefinementResult second = refine_vertex_map_sampling(p.model, first.polycube, p.polycube.planes_z, samples);
  ASSERT_TRUE(second.refined);
  expect_same_polycube(first.polycube, second.polycube, p.polycube.genus);
  expect_consistent_samples(p.model, second.polycube, samples, second.map);
  const MapDirectionAudit after = audit_map_direction(second.polycube.mesh, second.map.polycube_on_model_xyz, p.model);
  EXPECT_LE(bad(after), bad(input));
  EXPECT_LE(after.max_distance, 1e-3);
  EXPECT_NEAR(after.area_ratio, 1, 0.02);
  // Some new images lie on the model's edges (the crossings).
  const TriMesh& P = second.polycube.mesh;
  int on_edges = 0;
  for (int v = first.polycube.mesh.num_vertices(); v < P.num_vertices(); ++v)
    on_edges += closure_faces(p.model, second.map.polycube_on_model[v]).size() >= 2;
  EXPECT_GT(on_edges, 0);
}

TEST(MapRefinement, SameResultOnAnyNumberOfThreads) {
  const Pipeline& p = pipeline("sphere.off");
  MapRefinementOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const MapRefinementResult a = refine_map_sampling(p.model, p.polycube, p.map, one);
  const MapRefinementResult b = refine_map_sampling(p.model, p.polycube, p.map, two);
  EXPECT_EQ(a.polycube.mesh.V, b.polycube.mesh.V);
  EXPECT_EQ(a.polycube.mesh.F, b.polycube.mesh.F);
  EXPECT_EQ(a.map.polycube_on_model_xyz, b.map.polycube_on_model_xyz);
}

TEST(MapRefinement, NoRoundsReturnsTheInput) {
  const Pipeline& p = pipeline("sphere.off");
  MapRefinementOptions options;
  options.max_rounds = 0;
  const MapRefinementResult r = refine_map_sampling(p.model, p.polycube, p.map, options);
  EXPECT_FALSE(r.refined);
  EXPECT_EQ(r.polycube.mesh.V, p.polycube.polycube.mesh.V);
  EXPECT_EQ(r.polycube.mesh.F, p.polycube.polycube.mesh.F);
  EXPECT_EQ(r.map.polycube_on_model_xyz, p.map.polycube_on_model_xyz);
  EXPECT_EQ(r.map.model_on_polycube_xyz, p.map.model_on_polycube_xyz);
  EXPECT_EQ(r.vertices_after, r.vertices_before);
}

TEST(MapRefinement, RejectsMismatchedInput) {
  const Pipeline& p = pipeline("sphere.off");
  PolycubeMap truncated = p.map;
  truncated.polycube_on_model.pop_back();
  EXPECT_THROW(refine_map_sampling(p.model, p.polycube, truncated), std::invalid_argument);
  PolycubeMap no_data = p.map;
  no_data.data.reset();
  EXPECT_THROW(refine_map_sampling(p.model, p.polycube, no_data), std::invalid_argument);
  MapRefinementOptions bad_options;
  bad_options.max_vertex_factor = 0.5;
  EXPECT_THROW(refine_map_sampling(p.model, p.polycube, p.map, bad_options), std::invalid_argument);
}

}  // namespace
}  // namespace polycube
