// analyse_topology, the stage as a whole: on every closed mesh 1 minimum, 1 maximum, 2g saddles,
// every piece genus 0, Euler characteristics adding up, planes at most dz apart — also when the
// §3.2 planes miss the handles, when a handle sits in a monkey saddle, and whatever the scale,
// position or orientation of the input.
#include "polycube/topology.h"

#include "formats/mesh_io.h"
#include "polycube/errors.h"
#include "polycube/mesh_topology.h"
#include "polycube/validate.h"
#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

namespace polycube {
namespace {

const std::vector<std::string> kMeshes = {"sphere.off", "rotor.off",  "elk.off",      "knot.off",
                                          "joint.off",  "eight.off",  "helmet.off",   "anchor.off",
                                          "couplingdown.off", "torus_quad.off", "double-torus-example.off"};

void expect_valid_topology(const TriMesh& mesh, const TopologyResult& r, const TopologyOptions& options = {}) {
  const int chi = euler_characteristic(mesh.F, mesh.num_vertices());
  const int g = (2 - chi) / 2;
  EXPECT_EQ(r.euler, chi);
  EXPECT_EQ(r.genus, g);
  // §3.1: one minimum, one maximum, 2g saddles.
  EXPECT_EQ(r.critical.minima, std::vector<int>{r.harmonic.source});
  EXPECT_EQ(r.critical.maxima, std::vector<int>{r.harmonic.sink});
  EXPECT_EQ(r.critical.saddle_count(), 2 * g);
  // Planes: the ones sliced along, ascending, no gap wider than dz, none through a vertex.
  EXPECT_EQ(r.planes_z, r.sliced.planes);
  ASSERT_EQ(r.planes_normalised.size(), r.planes_z.size());
  const BoundingBox box = bounding_box(mesh.V);
  const double extent = box.extent().maxCoeff();
  std::vector<double> bounds = {0.0};
  for (size_t k = 0; k < r.planes_z.size(); ++k) {
    EXPECT_NEAR(r.planes_normalised[k], (r.planes_z[k] - box.min.z()) / extent, 1e-12);
    bounds.push_back(r.planes_normalised[k]);
  }
  bounds.push_back(box.extent().z() / extent);
  for (size_t k = 0; k + 1 < bounds.size(); ++k) {
    EXPECT_GT(bounds[k + 1], bounds[k]);
    EXPECT_LE(bounds[k + 1] - bounds[k], options.dz * (1 + 1e-9));
  }
  const std::set<double> planes(r.planes_z.begin(), r.planes_z.end());
  for (int v = 0; v < r.sliced.mesh.num_vertices(); ++v)
    EXPECT_EQ(planes.count(r.sliced.mesh.V(v, 2)) > 0, v >= r.sliced.input_vertices) << "vertex " << v;
  // The guarantee: genus-0 pieces that add up to the mesh, each bounded by its own two planes.
  int euler_sum = 0;
  for (const Piece& piece : r.sliced.pieces) {
    EXPECT_EQ(piece.genus, 0);
    euler_sum += piece.euler;
    for (size_t l = 0; l < piece.boundary_loops.size(); ++l) {
      const int plane = piece.loop_plane[l];
      EXPECT_TRUE(plane == piece.plane_below || plane == piece.plane_above);
      for (int v : piece.boundary_loops[l]) EXPECT_EQ(r.sliced.mesh.V(v, 2), r.planes_z[plane]);
    }
    Eigen::MatrixX3i PF(piece.faces.size(), 3);
    for (size_t k = 0; k < piece.faces.size(); ++k) PF.row(k) = r.sliced.mesh.F.row(piece.faces[k]);
    EXPECT_EQ(genus(PF, r.sliced.mesh.num_vertices()), 0);
  }
  EXPECT_EQ(euler_sum, chi);
  EXPECT_EQ(euler_characteristic(r.sliced.mesh.F, r.sliced.mesh.num_vertices()), chi);
}

TEST(Topology, TestMeshes) {
  for (const auto& name : kMeshes) {
    SCOPED_TRACE(name);
    const TriMesh mesh = test::load_test_mesh(name);
    expect_valid_topology(mesh, analyse_topology(mesh));
  }
}

TEST(Topology, GeneratedSurfacesOfGenusZeroToFour) {
  for (int g = 0; g <= 4; ++g) {
    SCOPED_TRACE("genus " + std::to_string(g));
    const TriMesh mesh = test::make_genus_surface(g, 32);
    const TopologyResult r = analyse_topology(mesh);
    expect_valid_topology(mesh, r);
    EXPECT_EQ(r.genus, g);
  }
}

TEST(Topology, AnyOrientation) {
  // Tilted inputs: handles no longer axis-aligned, saddles of a handle at other relative heights.
  for (const std::string name : {"eight.off", "helmet.off", "anchor.off", "couplingdown.off"}) {
    const TriMesh mesh = test::load_test_mesh(name);
    for (int k = 0; k < 6; ++k) {
      SCOPED_TRACE(name + " rotation " + std::to_string(k));
      const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.7 * k + 0.3, Eigen::Vector3d::UnitX()) *
                                 Eigen::AngleAxisd(1.3 * k, Eigen::Vector3d(0, 1, 1).normalized()))
                                    .toRotationMatrix();
      TriMesh rotated = mesh;
      rotated.V = mesh.V * R.transpose();
      expect_valid_topology(rotated, analyse_topology(rotated));
    }
  }
}

TEST(Topology, RefinementCutsHandlesThePaperPlanesMiss) {
  // One critical level and no dz planes: §3.2 gives no plane at all, every handle is left to
  // the genus refinement.
  TopologyOptions options;
  options.level_merge = 1;
  options.dz = 100;
  for (const std::string name : {"rotor.off", "eight.off", "helmet.off", "anchor.off", "couplingdown.off"}) {
    SCOPED_TRACE(name);
    const TriMesh mesh = test::load_test_mesh(name);
    const TopologyResult r = analyse_topology(mesh, options);
    EXPECT_TRUE(r.initial_planes.z.empty());
    EXPECT_GE(r.planes_added_for_genus, 1);
    EXPECT_EQ(static_cast<int>(r.planes_z.size()), r.planes_added_for_genus);
    expect_valid_topology(mesh, r, options);
  }
}

// A torus whose height has exactly one minimum, one maximum and one monkey saddle: the height
// sin(pi x) sin(pi y) sin(pi (x - y)) on the unit square torus (zero on three circles through the
// origin), on a grid bent slightly so that the six neighbours of the origin alternate in sign.
// The whole handle sits at the monkey saddle's level: no horizontal plane can cut it.
TriMesh monkey_saddle_torus(int n) {
  const double pi = 3.14159265358979323846;
  TriMesh mesh;
  mesh.V.resize(n * n, 3);
  mesh.F.resize(2 * n * n, 3);
  auto id = [n](int i, int j) { return (i % n) * n + (j % n); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u = double(i) / n, v = double(j) / n;
      const double x = u - 0.2 * std::sin(2 * pi * v) / (2 * pi), y = v + 0.2 * std::sin(2 * pi * u) / (2 * pi);
      const double phi = 2 * pi * u, theta = 2 * pi * (v + 0.25);
      mesh.V.row(id(i, j)) << (2 + std::cos(theta)) * std::cos(phi), (2 + std::cos(theta)) * std::sin(phi),
          std::sin(pi * x) * std::sin(pi * y) * std::sin(pi * (x - y));
    }
  int f = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      mesh.F.row(f++) << id(i, j), id(i + 1, j), id(i + 1, j + 1);
      mesh.F.row(f++) << id(i, j), id(i + 1, j + 1), id(i, j + 1);
    }
  return mesh;
}

TEST(Topology, HandleInAMonkeySaddleIsSplit) {
  const TriMesh mesh = monkey_saddle_torus(18);
  ASSERT_EQ(genus(mesh.F, mesh.num_vertices()), 1);
  const TopologyResult r = analyse_topology(mesh);
  EXPECT_EQ(r.split_saddles, 1);
  EXPECT_GT(r.sliced.input_vertices, mesh.num_vertices());
  expect_valid_topology(mesh, r);
  // Everything but the star of the split saddle (vertex 0) is the input surface.
  EXPECT_EQ(r.sliced.mesh.V.topRows(mesh.num_vertices()), mesh.V);
}

TEST(Topology, UnchangedUnderScalingAndTranslation) {
  for (const std::string name : {"helmet.off", "anchor.off"}) {
    const TriMesh mesh = test::load_test_mesh(name);
    const TopologyResult reference = analyse_topology(mesh);
    for (double scale : {1e-6, 1e6}) {
      for (double shift : {0.0, 100.0}) {
        SCOPED_TRACE(name + " scale " + std::to_string(scale) + " shift " + std::to_string(shift));
        TriMesh moved = mesh;
        moved.V = (mesh.V * scale).rowwise() + Eigen::RowVector3d(shift, 2 * shift, -3 * shift) * scale;
        const TopologyResult r = analyse_topology(moved);
        expect_valid_topology(moved, r);
        EXPECT_EQ(r.critical.saddles, reference.critical.saddles);
        EXPECT_EQ(r.planes_added_for_genus, reference.planes_added_for_genus);
        EXPECT_EQ(r.sliced.pieces.size(), reference.sliced.pieces.size());
        ASSERT_EQ(r.planes_normalised.size(), reference.planes_normalised.size());
        for (size_t k = 0; k < r.planes_normalised.size(); ++k)
          EXPECT_NEAR(r.planes_normalised[k], reference.planes_normalised[k], 1e-9);
      }
    }
  }
}

TEST(Topology, RejectsMeshesThatAreNotClosedSurfaces) {
  EXPECT_THROW(analyse_topology(test::open_cylinder()), MeshError);
  EXPECT_THROW(analyse_topology(test::two_tetrahedra()), MeshError);
  EXPECT_THROW(analyse_topology(test::nonmanifold_edge()), MeshError);
  EXPECT_THROW(analyse_topology(test::nonmanifold_vertex()), MeshError);
  EXPECT_THROW(analyse_topology(test::flipped_face_tetrahedron()), MeshError);
  TriMesh nan = test::make_sphere(1);
  nan.V(4, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(analyse_topology(nan), MeshError);
  TriMesh flat = test::make_sphere(1);
  flat.V.col(2).setZero();
  EXPECT_THROW(analyse_topology(flat), MeshError);
}

TEST(Topology, GivesUpBeyondThePlaneLimit) {
  const TriMesh mesh = test::load_test_mesh("couplingdown.off");
  TopologyOptions options;
  options.dz = 100;
  options.level_merge = 1;
  const int needed = static_cast<int>(analyse_topology(mesh, options).planes_z.size());
  ASSERT_GT(needed, 0);
  options.max_planes = needed - 1;
  EXPECT_THROW(analyse_topology(mesh, options), AlgorithmError);
}

}  // namespace
}  // namespace polycube
