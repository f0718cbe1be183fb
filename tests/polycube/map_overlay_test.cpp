// overlay_map: the common refinement of the pieces' two disk triangulations is a closed
// triangulation of P (same Euler characteristic, P's vertices kept, every triangle in its P face
// and oriented with it) on which the sampled map is φ: every image triangle lies in one model
// face (up to the cells collapsed for being too small) with that face's orientation, and the
// images tile the model (total area equal).
#include "polycube/map_audit.h"
#include "polycube/map_overlay.h"

#include "polycube/mesh_topology.h"
#include "support/test_support.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <string>

namespace polycube {
namespace {

double total_area(const TriMesh& mesh) {
  double area = 0;
  for (int f = 0; f < mesh.num_faces(); ++f)
    area += 0.5 * (mesh.V.row(mesh.F(f, 1)) - mesh.V.row(mesh.F(f, 0))).cross(mesh.V.row(mesh.F(f, 2)) - mesh.V.row(mesh.F(f, 0))).norm();
  return area;
}

Eigen::Vector3d face_normal(const TriMesh& mesh, int f) {
  const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
  return (b - a).cross(c - a);
}

int euler_characteristic(const TriMesh& mesh) {
  return mesh.num_vertices() - build_edge_map(mesh.F).num_edges() + mesh.num_faces();
}

class MapOverlayOnMeshes : public ::testing::TestWithParam<std::string> {};

TEST_P(MapOverlayOnMeshes, TilesBothSurfacesWithOrientedCells) {
  const std::string name = GetParam();
  const test::MappedModel& m = test::mapped_model(name);
  const TriMesh& P = m.polycube.polycube.mesh;
  const MapOverlay overlay = overlay_map(m.map);  // throws unless closed
  const TriMesh& R = overlay.polycube;
  EXPECT_EQ(overlay.uncovered_faces, 0) << name;
  ASSERT_EQ(overlay.face_parent.size(), R.num_faces());
  ASSERT_EQ(overlay.face_image.size(), R.num_faces());
  ASSERT_EQ(overlay.on_model_xyz.rows(), R.num_vertices());
  EXPECT_GT(R.num_faces(), P.num_faces()) << name;
  EXPECT_EQ(euler_characteristic(R), euler_characteristic(P)) << name;
  for (int v = 0; v < P.num_vertices(); ++v) ASSERT_LT((R.V.row(v) - P.V.row(v)).norm(), 1e-12) << name << " vertex " << v;

  const double p_area = total_area(P), m_area = total_area(m.model);
  EXPECT_NEAR(total_area(R) / p_area, 1.0, 1e-9) << name;
  TriMesh image = R;
  image.V = overlay.on_model_xyz;
  EXPECT_NEAR(total_area(image) / m_area, 1.0, 1e-9) << name;

  // Collapsing a cell too small for the audit moves its triangles' corners by at most the edge
  // collapsed (far below 1e-6 of the diagonal): those triangles are chords that close to their face.
  const double diagonal = (m.model.V.colwise().maxCoeff() - m.model.V.colwise().minCoeff()).norm();
  int off_parent = 0, reversed_on_p = 0, off_image_face = 0, reversed_on_m = 0, degenerate = 0;
  for (int f = 0; f < R.num_faces(); ++f) {
    // On P: inside the plane of its parent face, facing the same way (cells of zero area aside).
    const int parent = overlay.face_parent[f];
    const Eigen::Vector3d np = face_normal(P, parent).normalized();
    const Eigen::Vector3d nr = face_normal(R, f);
    for (int k = 0; k < 3; ++k) off_parent += std::abs((R.V.row(R.F(f, k)) - P.V.row(P.F(parent, 0))).dot(np)) > 1e-9;
    if (nr.norm() > 1e-14 * p_area) reversed_on_p += nr.dot(np) <= 0;
    // On M: inside its model face, facing the same way.
    const int mf = overlay.face_image[f];
    const Eigen::Vector3d nm = face_normal(m.model, mf).normalized();
    const Eigen::Vector3d ni = face_normal(image, f);
    for (int k = 0; k < 3; ++k)
      off_image_face += std::abs((image.V.row(image.F(f, k)) - m.model.V.row(m.model.F(mf, 0))).dot(nm)) > 1e-6 * diagonal;
    // No cell left below the audit's degenerate area on either surface (collapsed or flipped).
    degenerate += nr.norm() / 2 <= kAuditDegenerateArea * p_area || ni.norm() / 2 <= kAuditDegenerateArea * m_area;
    if (ni.norm() > 1e-14 * m_area && ni.dot(nm) <= 0) { ++reversed_on_m; ADD_FAILURE() << "reversed image " << f << ": image area " << ni.norm() / 2 << " of " << m_area << ", on P " << nr.norm() / 2; }
  }
  EXPECT_EQ(off_parent, 0) << name;
  EXPECT_EQ(reversed_on_p, 0) << name;
  EXPECT_EQ(off_image_face, 0) << name;
  EXPECT_EQ(reversed_on_m, 0) << name;
  EXPECT_EQ(degenerate, 0) << name;
}

INSTANTIATE_TEST_SUITE_P(Meshes, MapOverlayOnMeshes,
                         ::testing::Values("sphere.off", "torus_quad.off", "double-torus-example.off", "knot.off"),
                         [](const auto& info) { return test::test_name_of_file(info.param); });

}  // namespace
}  // namespace polycube
