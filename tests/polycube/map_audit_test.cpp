// audit_map / audit_map_direction: the outside check of a claimed bijection, on maps whose flaws
// are known by construction (swapped or reflected images, images off the surface, a double
// cover), and on chords across convex and concave polycube edges that must not count as flipped.
#include "polycube/closest_point.h"
#include "polycube/image_orientation.h"
#include "polycube/map_audit.h"

#include "polycube/target_surface.h"

#include "support/generated_meshes.h"

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <vector>

namespace polycube {
namespace {

using Lattice = std::array<int, 3>;

// Builds a mesh from lattice points, sharing equal points.
class LatticeMeshBuilder {
 public:
  int vertex(const Lattice& p) {
    auto [it, inserted] = index_.emplace(p, static_cast<int>(points_.size()));
    if (inserted) points_.push_back(p);
    return it->second;
  }
  void triangle(int a, int b, int c) { triangles_.push_back({a, b, c}); }
  // Adds the triangle oriented so that its normal has a positive dot product with outward.
  void oriented_triangle(const Lattice& a, const Lattice& b, const Lattice& c, const Eigen::Vector3d& outward) {
    const Eigen::Vector3d pa = point(a), pb = point(b), pc = point(c);
    if ((pb - pa).cross(pc - pa).dot(outward) > 0)
      triangle(vertex(a), vertex(b), vertex(c));
    else
      triangle(vertex(a), vertex(c), vertex(b));
  }
  static Eigen::Vector3d point(const Lattice& p) { return Eigen::Vector3d(p[0], p[1], p[2]); }

  TriMesh mesh() const {
    TriMesh mesh;
    mesh.V.resize(static_cast<Eigen::Index>(points_.size()), 3);
    for (size_t v = 0; v < points_.size(); ++v) mesh.V.row(static_cast<Eigen::Index>(v)) = point(points_[v]).transpose();
    mesh.F.resize(static_cast<Eigen::Index>(triangles_.size()), 3);
    for (size_t f = 0; f < triangles_.size(); ++f)
      for (int c = 0; c < 3; ++c) mesh.F(static_cast<Eigen::Index>(f), c) = triangles_[f][c];
    return mesh;
  }

 private:
  std::map<Lattice, int> index_;
  std::vector<Lattice> points_;
  std::vector<std::array<int, 3>> triangles_;
};

// A polycube made of unit voxels [0, size)^3 where solid(i, j, k): every exposed voxel face is a
// unit square of two triangles, counter-clockwise seen from outside (vertices on P's edges and
// corners included).
TriMesh voxel_polycube(int size, const std::function<bool(int, int, int)>& solid) {
  auto filled = [&](const Lattice& v) {
    for (int d = 0; d < 3; ++d)
      if (v[d] < 0 || v[d] >= size) return false;
    return solid(v[0], v[1], v[2]);
  };
  LatticeMeshBuilder builder;
  for (int i = 0; i < size; ++i)
    for (int j = 0; j < size; ++j)
      for (int k = 0; k < size; ++k) {
        if (!solid(i, j, k)) continue;
        for (int d = 0; d < 3; ++d)
          for (int s : {-1, 1}) {
            Lattice neighbour = {i, j, k};
            neighbour[d] += s;
            if (filled(neighbour)) continue;
            // Corners of the square in the (u, v) plane, e_u × e_v = e_d: counter-clockwise for +e_d.
            const int u = (d + 1) % 3, v = (d + 2) % 3;
            int corner[4];
            const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
            for (int c = 0; c < 4; ++c) {
              Lattice p = {i, j, k};
              p[d] += s > 0 ? 1 : 0;
              p[u] += du[c];
              p[v] += dv[c];
              corner[c] = builder.vertex(p);
            }
            if (s > 0) {
              builder.triangle(corner[0], corner[1], corner[2]);
              builder.triangle(corner[0], corner[2], corner[3]);
            } else {
              builder.triangle(corner[0], corner[2], corner[1]);
              builder.triangle(corner[0], corner[3], corner[2]);
            }
          }
      }
  return builder.mesh();
}

TriMesh lattice_cube(int n) {
  return voxel_polycube(n, [](int, int, int) { return true; });
}

// L-shape: [0, 2k) x [0, k) x [0, k) plus [0, k) x [0, k) x [k, 2k). Its concave edge runs along y
// at x = k, z = k, between the floor z = k (x > k, normal +z) and the wall x = k (z > k, normal +x).
TriMesh lattice_l_shape(int k) {
  return voxel_polycube(2 * k, [k](int i, int j, int l) { return j < k && (l < k || i < k); });
}

// The lattice cube [0, n]^3 with its edges and corners cut off: the convex hull of the lattice
// points inside the cube's faces (none on its edges). Each face keeps an (n-2) x (n-2) grid; along
// each cube edge a strip of quads joins the rows next to the edge on the two faces (chords across a
// convex 90° edge); at each corner one triangle joins three faces. Outward by convexity.
TriMesh chamfered_cube(int n) {
  LatticeMeshBuilder builder;
  const Eigen::Vector3d centre = Eigen::Vector3d::Constant(n / 2.0);
  auto add = [&](const Lattice& a, const Lattice& b, const Lattice& c) {
    const Eigen::Vector3d mid = (LatticeMeshBuilder::point(a) + LatticeMeshBuilder::point(b) + LatticeMeshBuilder::point(c)) / 3;
    builder.oriented_triangle(a, b, c, mid - centre);
  };
  auto quad = [&](const Lattice& a, const Lattice& b, const Lattice& c, const Lattice& d) {
    add(a, b, c);
    add(a, c, d);
  };
  auto inward = [n](int value) { return value == 0 ? 1 : n - 1; };
  for (int d = 0; d < 3; ++d)
    for (int side : {0, n}) {
      const int u = (d + 1) % 3, v = (d + 2) % 3;
      auto at = [&](int a, int b) {
        Lattice p{};
        p[d] = side;
        p[u] = a;
        p[v] = b;
        return p;
      };
      for (int a = 1; a + 1 <= n - 1; ++a)
        for (int b = 1; b + 1 <= n - 1; ++b) quad(at(a, b), at(a + 1, b), at(a + 1, b + 1), at(a, b + 1));
    }
  for (int axis = 0; axis < 3; ++axis)
    for (int vb : {0, n})
      for (int vc : {0, n}) {
        const int b = (axis + 1) % 3, c = (axis + 2) % 3;
        auto on_b = [&](int t) {  // on the face coordinate b = vb, next to the edge
          Lattice p{};
          p[axis] = t;
          p[b] = vb;
          p[c] = inward(vc);
          return p;
        };
        auto on_c = [&](int t) {
          Lattice p{};
          p[axis] = t;
          p[b] = inward(vb);
          p[c] = vc;
          return p;
        };
        for (int t = 1; t + 1 <= n - 1; ++t) quad(on_b(t), on_b(t + 1), on_c(t + 1), on_c(t));
      }
  for (int x : {0, n})
    for (int y : {0, n})
      for (int z : {0, n}) add({x, inward(y), inward(z)}, {inward(x), y, inward(z)}, {inward(x), inward(y), z});
  return builder.mesh();
}

TriMesh reversed(TriMesh mesh) {
  mesh.F.col(1).swap(mesh.F.col(2));
  return mesh;
}

// Every directed edge once, with its reverse: closed and consistently oriented; Euler V - E + F.
int euler_if_closed(const TriMesh& mesh) {
  std::map<std::pair<int, int>, int> directed;
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int c = 0; c < 3; ++c) ++directed[{mesh.F(f, c), mesh.F(f, (c + 1) % 3)}];
  for (const auto& [edge, count] : directed)
    if (count != 1 || !directed.count({edge.second, edge.first})) return std::numeric_limits<int>::min();
  return mesh.num_vertices() - static_cast<int>(directed.size()) / 2 + mesh.num_faces();
}

// Faces of the cube [0, n]^3 a point lies on.
int cube_faces_touched(const Eigen::Vector3d& p, int n) {
  int faces = 0;
  for (int d = 0; d < 3; ++d) faces += (p[d] == 0 || p[d] == n);
  return faces;
}

void expect_identity_ok(const TriMesh& mesh) {
  const MapAudit audit = audit_map(mesh, mesh, mesh.V, mesh.V);
  for (const MapDirectionAudit* d : {&audit.polycube_to_model, &audit.model_to_polycube}) {
    EXPECT_EQ(d->triangles, mesh.num_faces());
    EXPECT_EQ(d->flipped, 0);
    EXPECT_EQ(d->degenerate, 0);
    EXPECT_LE(d->max_distance, 1e-12);
    EXPECT_NEAR(d->area_ratio, 1, 1e-12);
    EXPECT_TRUE(d->ok);
  }
  EXPECT_NEAR(audit.distortion.eps_angle, 1, 1e-12);
  EXPECT_NEAR(audit.distortion.eps_area, 1, 1e-12);
  EXPECT_TRUE(audit.ok);
}

TEST(MapAudit, FixturesAreClosedOutwardPolycubesAndChords) {
  EXPECT_EQ(euler_if_closed(lattice_cube(4)), 2);
  EXPECT_EQ(euler_if_closed(lattice_l_shape(3)), 2);
  const TriMesh chamfered = chamfered_cube(6);
  EXPECT_EQ(euler_if_closed(chamfered), 2);
  EXPECT_GT(signed_volume(lattice_cube(4)), 0);
  EXPECT_NEAR(signed_volume(lattice_l_shape(3)), 3 * 27, 1e-9);
  EXPECT_GT(signed_volume(chamfered), 0);
  // Vertices of the chamfered cube lie inside the cube's faces; 12·2·4 strip triangles span two
  // faces and 8 corner triangles three.
  int across_two = 0, across_three = 0;
  for (int f = 0; f < chamfered.num_faces(); ++f) {
    int faces = 0;
    for (int d = 0; d < 3; ++d)
      for (int side : {0, 6}) {
        bool touches = false;
        for (int c = 0; c < 3; ++c) touches |= chamfered.V(chamfered.F(f, c), d) == side;
        faces += touches;
      }
    across_two += faces == 2;
    across_three += faces == 3;
  }
  for (int v = 0; v < chamfered.num_vertices(); ++v) EXPECT_EQ(cube_faces_touched(chamfered.V.row(v), 6), 1);
  EXPECT_EQ(across_two, 96);
  EXPECT_EQ(across_three, 8);
}

TEST(MapAudit, IdentityOnClosedMeshesIsOk) {
  for (const TriMesh& mesh : {test::make_sphere(3), test::make_torus(3, 1, 32, 16), lattice_cube(1), lattice_cube(4),
                              lattice_l_shape(3)})
    expect_identity_ok(mesh);
}

TEST(MapAudit, SwappedImagesAreFlipped) {
  const TriMesh sphere = test::make_sphere(3);
  Eigen::MatrixX3d image = sphere.V;
  const int a = sphere.F(0, 0), b = sphere.F(0, 1);
  image.row(a).swap(image.row(b));
  const MapAudit audit = audit_map(sphere, sphere, image, sphere.V);
  // The two triangles on edge ab keep their place with their orientation reversed.
  EXPECT_GE(audit.polycube_to_model.flipped, 2);
  EXPECT_LE(audit.polycube_to_model.max_distance, 1e-12) << "every image vertex is still on the surface";
  EXPECT_FALSE(audit.polycube_to_model.ok);
  EXPECT_TRUE(audit.model_to_polycube.ok);
  EXPECT_FALSE(audit.ok);
  // The same flaw in the other direction fails the audit as well.
  const MapAudit inverse = audit_map(sphere, sphere, sphere.V, image);
  EXPECT_TRUE(inverse.polycube_to_model.ok);
  EXPECT_GE(inverse.model_to_polycube.flipped, 2);
  EXPECT_FALSE(inverse.ok);
}

// The audit runs its searches and verdicts on threads and counts them in order: the same audit
// on one thread or several, to the last bit (a map with flips, images off the surface and
// degenerate triangles, both directions).
TEST(MapAudit, SameAuditOnOneThreadOrSeveral) {
  const TriMesh torus = test::make_torus(3, 1, 48, 24);
  Eigen::MatrixX3d image = torus.V;
  for (int f = 0; f < torus.num_faces(); f += 97) image.row(torus.F(f, 0)).swap(image.row(torus.F(f, 1)));
  for (int v = 5; v < torus.num_vertices(); v += 131) image.row(v) *= 1.01;
  image.row(torus.F(3, 1)) = image.row(torus.F(3, 0));
  MapAuditOptions one, several;
  one.threads = 1;
  several.threads = 3;
  const MapAudit a = audit_map(torus, torus, image, image, one), b = audit_map(torus, torus, image, image, several);
  EXPECT_GT(a.polycube_to_model.flipped, 0);
  EXPECT_GT(a.polycube_to_model.degenerate, 0);
  EXPECT_GT(a.polycube_to_model.max_distance, 0);
  for (const auto& [x, y] : {std::make_pair(a.polycube_to_model, b.polycube_to_model), std::make_pair(a.model_to_polycube, b.model_to_polycube)}) {
    EXPECT_EQ(x.flipped, y.flipped);
    EXPECT_EQ(x.degenerate, y.degenerate);
    EXPECT_EQ(x.max_distance, y.max_distance);
    EXPECT_EQ(x.area_ratio, y.area_ratio);
    EXPECT_EQ(x.ok, y.ok);
  }
}

TEST(MapAudit, ImageTriangleAcrossTheSolidCountsAsFlipped) {
  // A triangle with two corners on the top face and one on the bottom face of the cube stands in
  // the plane y = 2: its normal is tangent to every face it is near (dot product exactly 0), so
  // it does not lie on the surface with either orientation.
  const TriMesh cube = lattice_cube(4);
  TriMesh standing;
  standing.V.resize(3, 3);
  standing.V << 0, 2, 4, 4, 2, 4, 2, 2, 0;
  standing.F.resize(1, 3);
  standing.F << 0, 1, 2;
  EXPECT_EQ(audit_map_direction(standing, standing.V, cube).flipped, 1);
  EXPECT_EQ(audit_map_direction(reversed(standing), standing.V, cube).flipped, 1);
}

TEST(MapAudit, ChordFromOneFaceOfAThinPartToTheOppositeOneIsJudgedByTheFacesItPassesOver) {
  // A slab one unit thin in x. The chord has two corners on the cap x = 0 and one on the cap
  // x = 1, all 0.4 below the top z = 4, and faces up (+z) like the top it runs under. The faces
  // nearest its corners and centroid are caps with opposite normals (their sum is along x, the
  // dot product exactly 0); the finer look finds the top face, so it is not flipped. Reversed, it
  // faces away from the top and from every cap sum: flipped.
  const TriMesh slab = voxel_polycube(4, [](int i, int, int) { return i < 1; });
  TriMesh chord;
  chord.V.resize(3, 3);
  chord.V << 0, 1, 3.6, 1, 2, 3.6, 0, 3, 3.6;
  chord.F.resize(1, 3);
  chord.F << 0, 1, 2;
  ASSERT_GT(((chord.V.row(1) - chord.V.row(0)).cross(chord.V.row(2) - chord.V.row(0))).z(), 0);
  EXPECT_EQ(audit_map_direction(chord, chord.V, slab).flipped, 0);
  EXPECT_EQ(audit_map_direction(reversed(chord), chord.V, slab).flipped, 1);
}

TEST(MapAudit, ReflectionFlipsEveryTriangle) {
  // x -> -x maps the icosphere onto itself: every image is on the surface, areas and shapes are
  // kept (the distortion cannot see it), and every triangle is reversed.
  const TriMesh sphere = test::make_sphere(3);
  Eigen::MatrixX3d image = sphere.V;
  image.col(0) *= -1;
  const MapAudit audit = audit_map(sphere, sphere, image, sphere.V);
  EXPECT_EQ(audit.polycube_to_model.flipped, sphere.num_faces());
  EXPECT_LE(audit.polycube_to_model.max_distance, 1e-12);
  EXPECT_NEAR(audit.polycube_to_model.area_ratio, 1, 1e-12);
  EXPECT_NEAR(audit.distortion.eps_angle, 1, 1e-12);
  EXPECT_FALSE(audit.polycube_to_model.ok);
  EXPECT_FALSE(audit.ok);
}

TEST(MapAudit, ReflectedRegionOfAPolycubeFaceIsFlipped) {
  // The interior vertices of the top face of the lattice cube are mirrored within that face
  // (x -> n - x): images stay on P exactly, but the triangles inside the region are reversed.
  const int n = 4;
  const TriMesh cube = lattice_cube(n);
  Eigen::MatrixX3d image = cube.V;
  auto inside_top = [&](int v) {
    return cube.V(v, 2) == n && cube.V(v, 0) > 0 && cube.V(v, 0) < n && cube.V(v, 1) > 0 && cube.V(v, 1) < n;
  };
  for (int v = 0; v < cube.num_vertices(); ++v)
    if (inside_top(v)) image(v, 0) = n - cube.V(v, 0);
  int inside_triangles = 0;
  for (int f = 0; f < cube.num_faces(); ++f) inside_triangles += inside_top(cube.F(f, 0)) && inside_top(cube.F(f, 1)) && inside_top(cube.F(f, 2));
  ASSERT_GT(inside_triangles, 0);
  const MapDirectionAudit audit = audit_map_direction(cube, image, cube);
  EXPECT_GE(audit.flipped, inside_triangles);
  EXPECT_LE(audit.max_distance, 1e-12);
  EXPECT_FALSE(audit.ok);
}

TEST(MapAudit, ImagesOffTheSurfaceAreMeasured) {
  // Every image vertex moved outward along the sphere's radius by 1% of the bounding-box
  // diagonal. The icosphere is inscribed in the unit sphere, so the tangent plane at a vertex
  // supports it and the vertex itself stays the closest point: the distance is exactly 1%.
  const TriMesh sphere = test::make_sphere(3);
  const double offset = 0.01 * bounding_box(sphere.V).diagonal();
  const Eigen::MatrixX3d image = sphere.V + offset * sphere.V.rowwise().normalized();
  const MapAudit audit = audit_map(sphere, sphere, image, sphere.V);
  EXPECT_NEAR(audit.polycube_to_model.max_distance, 0.01, 1e-9);
  EXPECT_EQ(audit.polycube_to_model.flipped, 0);
  EXPECT_FALSE(audit.polycube_to_model.ok);
  EXPECT_FALSE(audit.ok);
  // The distance alone decides once the area is allowed to change.
  MapAuditOptions loose_area;
  loose_area.area_tolerance = 0.5;
  EXPECT_FALSE(audit_map_direction(sphere, image, sphere, loose_area).ok);
  loose_area.surface_tolerance = 0.0101;
  EXPECT_TRUE(audit_map_direction(sphere, image, sphere, loose_area).ok);
}

TEST(MapAudit, DoubleCoverIsCaughtByArea) {
  // Vertex (i, j) of the torus to vertex (2i, j): a covering of degree 2, orientation kept, every
  // image on the surface; only the total area (about twice the target's) shows it is no bijection.
  const int nu = 32, nv = 12;
  const TriMesh torus = test::make_torus(3, 1, nu, nv);
  Eigen::MatrixX3d image(torus.num_vertices(), 3);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) image.row(i + nu * j) = torus.V.row((2 * i) % nu + nu * j);
  const MapDirectionAudit audit = audit_map_direction(torus, image, torus);
  EXPECT_EQ(audit.flipped, 0);
  EXPECT_EQ(audit.degenerate, 0);
  EXPECT_LE(audit.max_distance, 1e-12);
  EXPECT_GT(audit.area_ratio, 1.9);
  EXPECT_LT(audit.area_ratio, 2.0);
  EXPECT_FALSE(audit.ok);
}

TEST(MapAudit, ChordsAcrossConvexEdgesAndCornersAreNotFlipped) {
  // The chamfered cube's vertices lie exactly on the lattice cube P, so its identity is a map onto
  // P whose strip and corner triangles are chords across P's convex edges and corners.
  const int n = 6;
  const TriMesh cube = lattice_cube(n), chamfered = chamfered_cube(n);
  const MapDirectionAudit audit = audit_map_direction(chamfered, chamfered.V, cube);
  EXPECT_EQ(audit.triangles, chamfered.num_faces());
  EXPECT_EQ(audit.flipped, 0);
  EXPECT_EQ(audit.degenerate, 0);
  EXPECT_LE(audit.max_distance, 1e-12);
  EXPECT_LT(audit.area_ratio, 1) << "chords cut the edges off";
  const MapDirectionAudit inverted = audit_map_direction(reversed(chamfered), chamfered.V, cube);
  EXPECT_EQ(inverted.flipped, chamfered.num_faces());
}

// The faces tied for closest to a point (TargetSurface::tied_faces) are every face through the
// point's closest point: at a corner of the lattice cube all the triangles round it, on an edge
// those of both squares, inside a square only the triangle holding it (on its diagonal, both);
// off the surface likewise, for the closest point. Checked against all faces by brute force.
TEST(MapAudit, TiedFacesAreEveryFaceThroughTheClosestPoint) {
  const TriMesh cube = lattice_cube(2);
  const TargetSurface surface(cube, "test");
  const double tolerance = kInFaceTolerance * surface.diagonal();
  struct Case {
    Eigen::Vector3d p;
    int at_least;
  };
  const std::vector<Case> cases = {{{0, 0, 0}, 3},          {{2, 2, 2}, 3},        {{1, 0, 0}, 2},          {{0.5, 0, 0}, 2},
                                   {{2, 0.7, 2}, 2},        {{1, 1, 0}, 4},        {{0.3, 0.6, 0}, 1},      {{0.25, 0.25, 0}, 1},
                                   {{-0.5, -0.5, 0.3}, 2},  {{-1, -1, -1}, 3},     {{0.4, 1.3, -0.7}, 1},   {{1.0 / 3, 2.0 / 3, 2}, 1}};
  for (const Case& c : cases) {
    const auto [f, distance] = surface.closest(c.p);
    std::vector<int> tied = {f};
    surface.tied_faces(c.p, f, tolerance, tied);
    std::sort(tied.begin(), tied.end());
    std::vector<int> brute;
    for (int g = 0; g < cube.num_faces(); ++g) {
      const Eigen::Vector3d a = cube.V.row(cube.F(g, 0)), b = cube.V.row(cube.F(g, 1)), d = cube.V.row(cube.F(g, 2));
      if ((closest_on_triangle(c.p, a, b, d).point - c.p).norm() <= distance + tolerance) brute.push_back(g);
    }
    EXPECT_EQ(tied, brute) << c.p.transpose();
    EXPECT_GE(static_cast<int>(tied.size()), c.at_least) << c.p.transpose();
  }
}

TEST(MapAudit, ChordsAcrossConcaveAndConvexEdgesOfAnLShapeAreNotFlipped) {
  // Bands of chord triangles on the L-shape, each with two vertices on one face and one on the
  // other, near to and far from the edge (skewed fans). Across the concave edge they fill the
  // inner corner (a fillet), across the convex edges they cut it off; both face +x+z outward.
  const int k = 4;
  const TriMesh l_shape = lattice_l_shape(k);
  LatticeMeshBuilder builder;
  const Eigen::Vector3d outward(1, 0, 1);
  // Edges along y: a point at distance i from the edge on the horizontal face (dx: its x direction
  // away from the edge) and at distance h on the vertical face (dz: its z direction).
  struct Edge {
    int x, z, dx, dz;
  };
  const Edge edges[3] = {{k, k, +1, +1} /* concave: floor x > k, wall z > k */,
                         {2 * k, k, -1, -1} /* convex: top z = k, end x = 2k */,
                         {k, 2 * k, -1, -1} /* convex: top z = 2k, wall x = k */};
  int chords = 0;
  for (const Edge& e : edges)
    for (int j = 0; j + 1 <= k; ++j)
      for (int i = 1; i < k; ++i)
        for (int h = 1; h < k; ++h) {
          const Lattice f0 = {e.x + e.dx * i, j, e.z}, f1 = {e.x + e.dx * i, j + 1, e.z};
          const Lattice w0 = {e.x, j, e.z + e.dz * h}, w1 = {e.x, j + 1, e.z + e.dz * h};
          builder.oriented_triangle(f0, f1, w0, outward);
          builder.oriented_triangle(f1, w1, w0, outward);
          chords += 2;
        }
  const TriMesh bands = builder.mesh();
  ASSERT_EQ(bands.num_faces(), chords);
  const MapDirectionAudit audit = audit_map_direction(bands, bands.V, l_shape);
  EXPECT_EQ(audit.flipped, 0);
  EXPECT_EQ(audit.degenerate, 0);
  EXPECT_LE(audit.max_distance, 1e-12);
  EXPECT_FALSE(audit.ok) << "a few bands do not cover P";
  EXPECT_EQ(audit_map_direction(reversed(bands), bands.V, l_shape).flipped, chords);
}

TEST(MapAudit, DegenerateAndNonFiniteImagesAreCounted) {
  const TriMesh sphere = test::make_sphere(2);
  Eigen::MatrixX3d collapsed = sphere.V;
  collapsed.row(sphere.F(0, 1)) = sphere.V.row(sphere.F(0, 0));
  const MapDirectionAudit a = audit_map_direction(sphere, collapsed, sphere);
  EXPECT_GE(a.degenerate, 2) << "both triangles on the collapsed edge";
  EXPECT_FALSE(a.ok);
  // Nearly collapsed (area ~1e-16 of the target's, not exactly 0) is degenerate too.
  Eigen::MatrixX3d nearly = sphere.V;
  nearly.row(sphere.F(0, 1)) = sphere.V.row(sphere.F(0, 0)) + 1e-14 * (sphere.V.row(sphere.F(0, 1)) - sphere.V.row(sphere.F(0, 0)));
  EXPECT_GE(audit_map_direction(sphere, nearly, sphere).degenerate, 2);

  Eigen::MatrixX3d broken = sphere.V;
  broken(7, 1) = std::numeric_limits<double>::quiet_NaN();
  int valence = 0;
  for (int f = 0; f < sphere.num_faces(); ++f) valence += (sphere.F.row(f).array() == 7).any();
  const MapAudit b = audit_map(sphere, sphere, broken, sphere.V);
  EXPECT_EQ(b.polycube_to_model.degenerate, valence);
  EXPECT_TRUE(std::isinf(b.polycube_to_model.max_distance));
  EXPECT_TRUE(std::isfinite(b.polycube_to_model.area_ratio));
  EXPECT_EQ(b.distortion.degenerate_image, valence);
  EXPECT_FALSE(b.ok);
}

// An image triangle lying inside one target face is judged by that face alone. Next to a sharp
// edge the faces closest to its corners can be the neighbour: on a tetrahedron with three right
// angles at the origin, the bottom's and the slanted face's area vectors sum to a vector at right
// angles to the bottom, so a triangle in the bottom whose corners' faces come out as the slanted
// one would be judged by a zero dot product (flipped) however it is oriented.
TEST(MapAudit, ImageInsideOneFaceIsJudgedByThatFace) {
  TriMesh tetrahedron;
  tetrahedron.V.resize(4, 3);
  tetrahedron.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  tetrahedron.F.resize(4, 3);
  tetrahedron.F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;  // outward: -z, -y, -x, (1, 1, 1)
  const TargetSurface target(tetrahedron, "test");
  const int slanted = 3;
  const Eigen::Vector3d a(0.1, 0.1, 0), b(0.1, 0.8, 0), c(0.8, 0.1, 0);  // in the bottom, facing -z
  ASSERT_LT((b - a).cross(c - a).z(), 0);
  EXPECT_EQ(target.judge(a, b, c, slanted, slanted, slanted), 0);
  EXPECT_EQ(target.judge(a, c, b, slanted, slanted, slanted), 1);
  // In the slanted face, corners on its edges: judged by the slanted face whichever faces the
  // corners report.
  const Eigen::Vector3d p(0.5, 0.5, 0), q(0, 0.5, 0.5), r(0.5, 0, 0.5);
  ASSERT_GT((q - p).cross(r - p).dot(Eigen::Vector3d(1, 1, 1)), 0);
  EXPECT_EQ(target.judge(p, q, r, 0, 1, 2), 0);
  EXPECT_EQ(target.judge(p, r, q, 0, 1, 2), 1);
}

TEST(MapAudit, RejectsBadArguments) {
  const TriMesh sphere = test::make_sphere(1);
  EXPECT_THROW(audit_map(sphere, sphere, Eigen::MatrixX3d::Zero(3, 3), sphere.V), std::invalid_argument);
  EXPECT_THROW(audit_map(sphere, sphere, sphere.V, Eigen::MatrixX3d::Zero(3, 3)), std::invalid_argument);
  EXPECT_THROW(audit_map_direction(sphere, sphere.V, TriMesh{}), std::invalid_argument);
  TriMesh bad_index = sphere;
  bad_index.F(1, 2) = -1;
  EXPECT_THROW(audit_map_direction(bad_index, sphere.V, sphere), std::invalid_argument);
  MapAuditOptions negative;
  negative.surface_tolerance = -1;
  EXPECT_THROW(audit_map_direction(sphere, sphere.V, sphere, negative), std::invalid_argument);
  TriMesh point = sphere;
  point.V.setZero();
  EXPECT_THROW(audit_map_direction(sphere, sphere.V, point), std::invalid_argument);
}

}  // namespace
}  // namespace polycube
