// Auto-orientation: principal axes and normal axes of a known box, snapping of aligned models, the
// candidate scoring keeps a valid winner, and the full-budget fallback.
#include "polycube/align.h"
#include "polycube/mesh_topology.h"
#include "polycube/simplify.h"

#include "support/generated_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <atomic>
#include <set>
#include <stdexcept>
#include <vector>

namespace polycube {
namespace {

using namespace test;

// A box 4 x 2 x 1 as a closed triangle mesh (6 faces, 12 triangles), centred at c.
TriMesh box(const Eigen::Vector3d& c) {
  TriMesh m;
  m.V.resize(8, 3);
  for (int i = 0; i < 8; ++i) m.V.row(i) = c.transpose() + Eigen::RowVector3d((i & 1 ? 2 : -2), (i & 2 ? 1 : -1), (i & 4 ? 0.5 : -0.5));
  m.F.resize(12, 3);
  m.F << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5;
  return m;
}

TEST(Align, PrincipalAxesOfATurnedBoxAreItsEdges) {
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const TriMesh turned = rotated(box(Eigen::Vector3d(3, -1, 2)), turn);
  const Eigen::Matrix3d axes = principal_axes(turned);
  EXPECT_NEAR(axes.determinant(), 1.0, 1e-12);
  // Longest spread first: the box's x edge (length 4), then y, then z, up to sign.
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(std::abs(axes.row(i).dot(turn.col(i))), 1.0, 1e-9) << "axis " << i;
}

// A rod 1000 times as long as wide, turned: its copy has the principal axes scaled so that the
// spreads along them come within the ratio asked (the longest shrunk, the others grown, volume
// kept); a model not that long gets none.
TEST(Align, AnEqualisedCopyBringsTheSpreadsWithinTheRatio) {
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 1).normalized()).toRotationMatrix();
  const TriMesh rod = rotated(test::make_rod(0.001, 1, 24), turn);
  const std::optional<EqualisedCopy> e = equalised_copy(rod);
  ASSERT_TRUE(e);
  EXPECT_GT(e->deviations(0), 300 * e->deviations(1));
  EXPECT_NEAR(e->deviations(1), e->deviations(2), 1e-3 * e->deviations(1));
  EXPECT_NEAR(e->scales.prod(), 1.0, 1e-12);
  EXPECT_LT(e->scales(0), 1);
  EXPECT_GT(e->scales(2), 1);
  EXPECT_LT((e->axes - principal_axes(rod)).norm(), 1e-15);
  // The copy is the rod turned by the axes and scaled along them.
  EXPECT_LT((e->copy.V - rotated(rod, e->scales.asDiagonal() * e->axes).V).norm(), 1e-15);
  // Its own standard deviations are about 4 apart: the ratio, but its caps weigh more against its
  // sides once scaled (the surface's measure is not carried linearly).
  double copy_spread = 0;
  principal_axes(e->copy, &copy_spread);
  EXPECT_GT(copy_spread, 16 * 0.9);
  EXPECT_LT(copy_spread, 25);
  // Turned by a candidate (x up: a cyclic permutation), the copy's scales and the model's rotation
  // follow the axes.
  const Eigen::Matrix3d x_up = (Eigen::Matrix3d() << 0, 1, 0, 0, 0, 1, 1, 0, 0).finished();
  EXPECT_EQ(e->turned_scales(x_up), Eigen::Vector3d(e->scales(1), e->scales(2), e->scales(0)));
  EXPECT_LT((rotated(rotated(rod, e->turned_axes(x_up)), e->turned_scales(x_up).asDiagonal()).V - rotated(e->copy, x_up).V).norm(), 1e-12);

  EXPECT_FALSE(equalised_copy(test::make_sphere(2)));
  EXPECT_FALSE(equalised_copy(test::make_rod(0.01, 1, 24)));  // 100 : 1, a deviation ratio of 41
}

TEST(Align, AlignedModelsAreNotTilted) {
  // A box turned by 2 degrees snaps back to the coordinate axes; by 20 degrees it does not.
  const Eigen::Matrix3d small = Eigen::AngleAxisd(2 * M_PI / 180, Eigen::Vector3d(0, 0, 1)).toRotationMatrix();
  const Eigen::Matrix3d axes = principal_axes(rotated(box(Eigen::Vector3d::Zero()), small));
  EXPECT_EQ((axes.cwiseAbs() - Eigen::Matrix3d::Identity()).norm(), 0.0);
  const Eigen::Matrix3d large = Eigen::AngleAxisd(20 * M_PI / 180, Eigen::Vector3d(0, 0, 1)).toRotationMatrix();
  EXPECT_GT((principal_axes(rotated(box(Eigen::Vector3d::Zero()), large)).cwiseAbs() - Eigen::Matrix3d::Identity()).norm(), 0.1);
}

// A rotation is a candidate once. The principal axes of an axis-aligned box, snapped, are signed
// coordinate axes; where they are the input axes or a cyclic permutation of them (all signs
// positive), each principal candidate is an input-frame candidate again (the same stages and
// map) and is left out; turned by 180 degrees (other signs) they stay.
TEST(Align, ARotationIsACandidateOnce) {
  AlignmentOptions options;
  options.mapped_candidates = 0;
  int repeating = 0;
  for (int shift = 0; shift < 3; ++shift) {
    TriMesh m = box(Eigen::Vector3d(1, 2, 3));
    for (int c = 0; c < 3; ++c) m.V.col(c) = box(Eigen::Vector3d(1, 2, 3)).V.col((c + shift) % 3);  // the long side along another axis
    const Eigen::Matrix3d pca = principal_axes(m);
    ASSERT_EQ((pca.cwiseAbs() * Eigen::Vector3d::Ones() - Eigen::Vector3d::Ones()).norm(), 0.0) << "snapped to the axes";
    const bool cyclic = pca.minCoeff() >= 0;
    repeating += cyclic;
    const Alignment a = choose_alignment(m, TopologyOptions{}, PolycubeOptions{}, options);
    EXPECT_EQ(a.candidates.size(), cyclic ? 3u : 6u) << "shift " << shift;
    for (size_t i = 0; i < a.candidates.size(); ++i)
      for (size_t j = 0; j < i; ++j) EXPECT_FALSE(a.candidates[i].rotation == a.candidates[j].rotation) << a.candidates[i].name;
  }
  EXPECT_GT(repeating, 0) << "no placement of the box repeats the input frame: the test tests nothing";
}

// A box turned anyhow: its faces' normals give back its frame (up to the cube's rotations), even
// for a box whose proportions make the principal axes useless (a cube: any frame is principal).
TEST(Align, NormalAxesOfATurnedBoxAreItsFaces) {
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(1.1, Eigen::Vector3d(-2, 1, 4).normalized()).toRotationMatrix();
  TriMesh cube = box(Eigen::Vector3d(1, 2, 3));
  cube.V.col(0) /= 2;  // 2 x 2 x 1
  cube.V.col(2) *= 2;  // 2 x 2 x 2
  const TriMesh turned = rotated(cube, turn);
  const Eigen::Matrix3d axes = normal_axes(turned);
  EXPECT_NEAR(axes.determinant(), 1.0, 1e-12);
  EXPECT_TRUE(same_axes(axes, turn.transpose(), 0.05)) << axes;
  EXPECT_FALSE(same_axes(axes, Eigen::Matrix3d::Identity(), 5));
  // In the input frame already (up to 2°): exactly the coordinate axes.
  const Eigen::Matrix3d small = Eigen::AngleAxisd(2 * M_PI / 180, Eigen::Vector3d(1, 0, 0)).toRotationMatrix();
  const Eigen::Matrix3d snapped = normal_axes(rotated(cube, small));
  EXPECT_TRUE(same_axes(snapped, Eigen::Matrix3d::Identity(), 1e-9)) << snapped;
  EXPECT_EQ(snapped.cwiseAbs().sum(), 3.0);
}

// A CAD part turned anyhow: its normals give its own frame back, which becomes a candidate.
TEST(Align, TurnedCadPartGetsItsFrameBack) {
  const TriMesh joint = load_test_mesh("joint.off");
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.9, Eigen::Vector3d(3, -1, 2).normalized()).toRotationMatrix();
  const TriMesh turned = rotated(joint, turn);
  double own = 0, after = 0;
  const Eigen::Matrix3d frame = normal_axes(joint, 20000, &own);
  const Eigen::Matrix3d found = normal_axes(turned, 20000, &after);
  EXPECT_LT(own, 0.1);
  EXPECT_NEAR(after, own, 1e-6);
  EXPECT_TRUE(same_axes(found, frame * turn.transpose(), 0.1)) << found << "\n" << frame * turn.transpose();
  AlignmentOptions options;
  options.mapped_candidates = 0;
  const Alignment a = choose_alignment(turned, TopologyOptions{}, PolycubeOptions{}, options);
  ASSERT_EQ(a.candidates.size(), 9u);
  EXPECT_EQ(a.candidates[6].name.rfind("normal axes", 0), 0u);
  EXPECT_LT((a.candidates[6].rotation - found).norm(), 1e-12);
}

// A cube's principal axes are any axes (its variances are equal; rounding picks them), so they
// are no candidate while another passes; a box's are (its spread is 16: 4² / 1²).
TEST(Align, PrincipalAxesOfACubeAreHeldInReserve) {
  TriMesh cube = box(Eigen::Vector3d(1, 2, 3));
  cube.V.col(0) /= 2;
  cube.V.col(2) *= 2;
  double spread = 0;
  principal_axes(cube, &spread);
  EXPECT_NEAR(spread, 1.0, 1e-9);
  principal_axes(box(Eigen::Vector3d::Zero()), &spread);
  EXPECT_GT(spread, AlignmentOptions{}.principal_axes_spread);
  AlignmentOptions options;
  options.mapped_candidates = 0;
  const Alignment a = choose_alignment(cube, TopologyOptions{}, PolycubeOptions{}, options);
  ASSERT_EQ(a.candidates.size(), 3u);
  for (const AlignmentCandidate& c : a.candidates) EXPECT_EQ(c.name.rfind("input frame", 0), 0u) << c.name;
  EXPECT_GE(a.chosen, 0);
  // Nearly a cube (spread 1.16, below the ratio): held in reserve too, and a candidate when the
  // ratio asked is 1. (Its principal axes, z then y then x, are no turn of the input frame's:
  // a cube's own may be, and then they are not candidates again: ARotationIsACandidateOnce.)
  TriMesh near_cube = cube;
  near_cube.V.col(1) *= 1.05;
  near_cube.V.col(2) *= 1.1;
  principal_axes(near_cube, &spread);
  EXPECT_GT(spread, 1.1);
  EXPECT_LT(spread, AlignmentOptions{}.principal_axes_spread);
  EXPECT_EQ(choose_alignment(near_cube, TopologyOptions{}, PolycubeOptions{}, options).candidates.size(), 3u);
  options.principal_axes_spread = 1;
  const Alignment b = choose_alignment(near_cube, TopologyOptions{}, PolycubeOptions{}, options);
  ASSERT_EQ(b.candidates.size(), 6u);
  EXPECT_EQ(b.candidates[3].name.rfind("principal axes", 0), 0u) << b.candidates[3].name;
}

// The caller's stop ends the search: once it says so no candidate's step starts, and nothing is
// chosen (a time limit, for a search whose result the caller can do without).
TEST(Align, StopEndsTheSearch) {
  const TriMesh model = load_test_mesh("knot.off");
  AlignmentOptions options;
  options.threads = 1;
  options.stop = [] { return true; };
  const Alignment none = choose_alignment(model, TopologyOptions{}, PolycubeOptions{}, options);
  EXPECT_TRUE(none.stopped);
  EXPECT_EQ(none.chosen, -1);
  EXPECT_FALSE(none.polycube);
  EXPECT_TRUE(none.alternatives.empty());
  ASSERT_FALSE(none.candidates.empty());
  for (const AlignmentCandidate& c : none.candidates) {
    EXPECT_LT(c.corners, 0) << c.name;
    EXPECT_LT(c.flipped, 0) << c.name;
    EXPECT_EQ(c.error, "not built: the search was stopped") << c.name;
  }
  // Asked once per step: on one thread, a stop that says so at its third question lets exactly
  // two candidates' polycubes be built, and no map.
  std::atomic<int> asked{0};
  options.stop = [&asked] { return ++asked > 2; };
  const Alignment two = choose_alignment(model, TopologyOptions{}, PolycubeOptions{}, options);
  EXPECT_TRUE(two.stopped);
  EXPECT_EQ(two.chosen, -1);
  int built = 0;
  for (const AlignmentCandidate& c : two.candidates) {
    built += c.error != "not built: the search was stopped";
    EXPECT_LT(c.flipped, 0) << c.name;
  }
  EXPECT_EQ(built, 2);
  EXPECT_GT(two.candidates.size(), 2u);
}

// Nothing passes a scoring budget of one round and no inserted plane (rotor needs several rounds
// and planes in its input frame): the candidates are built again with four times that budget, the
// one with the fewest corners wins (or, when none passes that either, the first that builds with
// the full budget), with its topology and polycube but unmapped.
TEST(Align, FallsBackToALargerBudget) {
  const TriMesh model = load_test_mesh("rotor.off");
  AlignmentOptions tight;
  tight.max_rounds = 1;
  tight.max_inserted_planes = 0;
  tight.full_budget_fallback = false;
  const Alignment none = choose_alignment(model, TopologyOptions{}, PolycubeOptions{}, tight);
  for (const AlignmentCandidate& c : none.candidates) ASSERT_LT(c.corners, 0) << c.name << " passed one round";
  EXPECT_EQ(none.chosen, -1);
  EXPECT_FALSE(none.polycube);
  tight.full_budget_fallback = true;
  const Alignment a = choose_alignment(model, TopologyOptions{}, PolycubeOptions{}, tight);
  ASSERT_GE(a.chosen, 0);
  const AlignmentCandidate& w = a.candidates[a.chosen];
  EXPECT_TRUE(w.fallback_budget);
  for (const AlignmentCandidate& c : a.candidates)
    if (c.corners >= 0) {
      EXPECT_TRUE(c.fallback_budget) << c.name;
      EXPECT_GE(c.corners, w.corners) << c.name;
    }
  ASSERT_TRUE(a.polycube);
  EXPECT_EQ(a.polycube->genus, 1);
  EXPECT_EQ(static_cast<int>(a.polycube->polycube.corners.size()), w.corners);
  EXPECT_FALSE(a.map);
  EXPECT_EQ(a.rotation, w.rotation);
}

// The checks' work is part of the scoring budget: with room for almost none, every candidate
// fails under it (and under the fallback's) with the budget named and its work reported, and the
// caller's full budget, which has no such limit, still gives a polycube.
TEST(Align, ChecksWorkIsPartOfTheScoringBudget) {
  const TriMesh model = load_test_mesh("sphere.off");
  AlignmentOptions options;
  options.max_rasterized_cells = 1;
  options.max_fallback_rasterized_cells = 4;
  options.mapped_candidates = 0;
  const Alignment a = choose_alignment(model, TopologyOptions{}, PolycubeOptions{}, options);
  ASSERT_GE(a.chosen, 0);
  ASSERT_TRUE(a.polycube);
  EXPECT_GT(a.polycube->rasterized_cells, 4);
  for (const AlignmentCandidate& c : a.candidates) {
    EXPECT_GT(c.rasterized_cells, 0) << c.name;
    if (c.corners < 0) {
      EXPECT_NE(c.error.find("rasterized"), std::string::npos) << c.name << ": " << c.error;
    }
  }
  EXPECT_TRUE(a.candidates[a.chosen].fallback_budget);
}

// The fallback's cells are budgeted on their own, not as four times the scoring's: with room for
// almost none in the scoring and the default in the fallback, every candidate passes in the
// fallback (all of them are built there at once), each with more cells than four times the
// scoring's budget. (Were the fallback's cells four times the scoring's, all would fail there
// and only the first to pass the caller's full budget, built one at a time, would have corners.)
TEST(Align, TheFallbackHasItsOwnCellBudget) {
  const TriMesh model = load_test_mesh("sphere.off");
  AlignmentOptions options;
  options.max_rasterized_cells = 1;
  options.mapped_candidates = 0;
  const Alignment a = choose_alignment(model, TopologyOptions{}, PolycubeOptions{}, options);
  ASSERT_GE(a.chosen, 0);
  ASSERT_TRUE(a.polycube);
  int passed = 0;
  for (const AlignmentCandidate& c : a.candidates) {
    if (c.corners < 0) continue;
    ++passed;
    EXPECT_TRUE(c.fallback_budget) << c.name;
    EXPECT_GT(c.rasterized_cells, 4) << c.name;
    EXPECT_LE(static_cast<double>(c.rasterized_cells), options.max_fallback_rasterized_cells) << c.name;
  }
  EXPECT_GE(passed, 2);
}

// A model above the proxy threshold is scored on a simplified copy (same genus); the winner's
// topology and polycube are of the model itself, its map is left to the caller.
TEST(Align, LargeModelsAreScoredOnASimplifiedCopy) {
  const TriMesh model = load_test_mesh("knot.off");  // 4160 faces, genus 1
  AlignmentOptions options;
  options.proxy_above = 2000;
  options.proxy_faces = 1500;
  const Alignment a = choose_alignment(model, TopologyOptions{}, PolycubeOptions{}, options);
  EXPECT_GT(a.proxy_faces, 1000);
  EXPECT_LE(a.proxy_faces, 1600);
  ASSERT_GE(a.chosen, 0);
  ASSERT_TRUE(a.topology);
  ASSERT_TRUE(a.polycube);
  EXPECT_FALSE(a.map);
  EXPECT_EQ(a.polycube->genus, 1);
  EXPECT_EQ(a.topology->sliced.input_vertices, model.num_vertices()) << "stages of the model itself";
  EXPECT_EQ(a.rotation, a.candidates[a.chosen].rotation);
  // Below the threshold: the model itself, mapped.
  const Alignment b = choose_alignment(model, TopologyOptions{}, PolycubeOptions{});
  EXPECT_EQ(b.proxy_faces, 0);
  EXPECT_TRUE(b.map);
}

// The simplified copy keeps the genus and the single component, and has about the faces asked.
TEST(Align, SimplifiedMeshKeepsTheTopology) {
  for (const char* name : {"knot.off", "couplingdown.off", "elk.off"}) {
    const TriMesh model = load_test_mesh(name);
    const TriMesh coarse = simplified_mesh(model, 800);
    const int euler = model.num_vertices() - model.num_faces() / 2;  // V - E + F with E = 3F/2
    EXPECT_EQ(coarse.num_vertices() - coarse.num_faces() / 2, euler) << name;
    EXPECT_EQ(connected_components(coarse.F, coarse.num_vertices()), 1) << name;
    EXPECT_LE(coarse.num_faces(), 900) << name;
    EXPECT_GE(coarse.num_faces(), 500) << name;
    EXPECT_EQ(simplified_mesh(coarse, 100000).F, coarse.F) << "a small mesh comes back unchanged";
  }
  EXPECT_THROW(simplified_mesh(load_test_mesh("sphere.off"), 2), std::invalid_argument);
}

// The winner is the mapped candidate with the fewest flipped triangles (then least ε_angle); the
// three with the fewest corners are always mapped; the winner's stages come with it.
TEST(Align, ChoosesTheMappedCandidateWithFewestFlips) {
  const TriMesh model = load_test_mesh("knot.off");
  const Alignment a = choose_alignment(model, TopologyOptions{}, PolycubeOptions{});
  // Input frame and principal axes; the knot's normals align with no frame (a smooth tube).
  double misalignment = 0;
  normal_axes(model, 20000, &misalignment);
  EXPECT_GT(misalignment, 0.15);
  // Six orientations; the knot has few vertices (2080), so each mapped one comes again with a
  // finer P (same rotation, topology and polycube, so the same corners).
  std::vector<const AlignmentCandidate*> orientations, finer;
  for (const AlignmentCandidate& c : a.candidates)
    (c.name.size() > 9 && c.name.substr(c.name.size() - 9) == ", finer P" ? finer : orientations).push_back(&c);
  ASSERT_EQ(orientations.size(), 6u);
  ASSERT_GE(finer.size(), 2u);
  for (const AlignmentCandidate* f : finer) {
    const auto original = std::find_if(orientations.begin(), orientations.end(),
                                       [&](const AlignmentCandidate* c) { return c->name + ", finer P" == f->name; });
    ASSERT_NE(original, orientations.end()) << f->name;
    EXPECT_GE((*original)->flipped, 0) << "only mapped candidates get a finer variant";
    EXPECT_EQ(f->rotation, (*original)->rotation);
    EXPECT_EQ(f->corners, (*original)->corners);
    EXPECT_GE(f->flipped, 0) << "the variant is mapped";
  }
  ASSERT_GE(a.chosen, 0);
  const AlignmentCandidate& w = a.candidates[a.chosen];
  ASSERT_GE(w.flipped, 0) << "the winner was mapped";
  std::vector<int> corners;
  for (const AlignmentCandidate& c : a.candidates) {
    EXPECT_NEAR(c.rotation.determinant(), 1.0, 1e-9) << c.name;
    if (c.corners >= 0) corners.push_back(c.corners);
    if (c.flipped >= 0) {
      EXPECT_TRUE(c.flipped > w.flipped || (c.flipped == w.flipped && c.eps_angle >= w.eps_angle)) << c.name;
    }
  }
  std::sort(corners.begin(), corners.end());
  int mapped_with_few_corners = 0;
  for (const AlignmentCandidate& c : a.candidates)
    if (c.corners >= 0 && c.corners <= corners[std::min<size_t>(2, corners.size() - 1)] && c.flipped >= 0) ++mapped_with_few_corners;
  EXPECT_GE(mapped_with_few_corners, std::min<int>(3, static_cast<int>(corners.size())));
  ASSERT_TRUE(a.polycube);
  ASSERT_TRUE(a.map);
  EXPECT_EQ(static_cast<int>(a.polycube->polycube.corners.size()), w.corners);
  EXPECT_EQ(a.polycube->genus, 1);
  EXPECT_EQ(a.map->polycube_on_model_xyz.rows(), a.polycube->polycube.mesh.num_vertices());
  EXPECT_EQ(a.rotation, w.rotation);
  if (w.name.find(", finer P") != std::string::npos) {
    EXPECT_GT(a.polycube->polycube.mesh.num_vertices(), 2 * model.num_vertices()) << "about 20 000 asked";
  }
  // The alternatives: two other mapped candidates with their own stages, the first of the
  // winner's other P density, the second the best of the rest by the score.
  auto finer_name = [](const AlignmentCandidate& c) { return c.name.find(", finer P") != std::string::npos; };
  ASSERT_EQ(a.alternatives.size(), 2u);
  EXPECT_NE(finer_name(a.candidates[a.alternatives[0].candidate]), finer_name(w));
  for (const AlignedStages& s : a.alternatives) {
    ASSERT_GE(s.candidate, 0);
    EXPECT_NE(s.candidate, a.chosen);
    const AlignmentCandidate& c = a.candidates[s.candidate];
    EXPECT_GE(c.flipped, 0) << c.name << " was mapped";
    ASSERT_TRUE(s.topology && s.polycube && s.map) << c.name;
    EXPECT_EQ(static_cast<int>(s.polycube->polycube.corners.size()), c.corners);
    EXPECT_EQ(s.map->polycube_on_model_xyz.rows(), s.polycube->polycube.mesh.num_vertices());
  }
  EXPECT_NE(a.alternatives[0].candidate, a.alternatives[1].candidate);
  const AlignmentCandidate& second = a.candidates[a.alternatives[1].candidate];
  for (size_t i = 0; i < a.candidates.size(); ++i) {
    const AlignmentCandidate& c = a.candidates[i];
    if (c.flipped < 0 || static_cast<int>(i) == a.chosen || static_cast<int>(i) == a.alternatives[0].candidate) continue;
    EXPECT_TRUE(c.flipped > second.flipped || (c.flipped == second.flipped && c.eps_angle >= second.eps_angle)) << c.name;
  }
  // The reserve: every other candidate built, once, with its topology and polycube but no map,
  // the mapped ones by the score first.
  std::set<int> listed{a.chosen, a.alternatives[0].candidate, a.alternatives[1].candidate};
  for (size_t k = 0; k < a.reserve.size(); ++k) {
    const AlignedStages& s = a.reserve[k];
    ASSERT_GE(s.candidate, 0);
    EXPECT_TRUE(listed.insert(s.candidate).second) << a.candidates[s.candidate].name << " listed twice";
    ASSERT_TRUE(s.topology && s.polycube) << a.candidates[s.candidate].name;
    EXPECT_FALSE(s.map);
    EXPECT_EQ(s.rotation, a.candidates[s.candidate].rotation);
    EXPECT_EQ(static_cast<int>(s.polycube->polycube.corners.size()), a.candidates[s.candidate].corners);
    if (k == 0) continue;
    const AlignmentCandidate &before = a.candidates[a.reserve[k - 1].candidate], &c = a.candidates[s.candidate];
    if (before.flipped < 0) {
      EXPECT_LT(c.flipped, 0) << "a mapped candidate after an unmapped one";
    } else if (c.flipped >= 0) {
      EXPECT_TRUE(c.flipped > before.flipped || (c.flipped == before.flipped && c.eps_angle >= before.eps_angle)) << c.name;
    }
  }
  for (size_t i = 0; i < a.candidates.size(); ++i)
    if (a.candidates[i].corners >= 0 && a.candidates[i].error.empty()) {
      EXPECT_EQ(listed.count(static_cast<int>(i)), 1u) << a.candidates[i].name;
    }
  // Without the finer variants: only the six orientations.
  AlignmentOptions plain;
  plain.fine_polycube_vertices = 0;
  EXPECT_EQ(choose_alignment(model, TopologyOptions{}, PolycubeOptions{}, plain).candidates.size(), 6u);
}

// A candidate whose repair rounds ran out with few slabs still failing is a near miss: when every
// map tried has flips, it gets four times the scoring budget and its map, and competes; one that
// failed otherwise, or with more slabs failing, is not built again.
TEST(Align, NearMissesGetASecondChanceWhenEveryMapFlips) {
  const TriMesh model = load_test_mesh("rotor.off");
  AlignmentOptions tight;
  tight.max_rounds = 3;  // rotor: four orientations run out of rounds, three with 1 slab failing, one with 2
  tight.near_miss_slabs = 0;
  const Alignment first = choose_alignment(model, TopologyOptions{}, PolycubeOptions{}, tight);
  int near = 0, mapped_clean = 0;
  for (const AlignmentCandidate& c : first.candidates) {
    EXPECT_FALSE(c.fallback_budget) << c.name;
    if (c.failing_slabs > 0) {
      EXPECT_LT(c.corners, 0) << c.name;
      EXPECT_NE(c.error.find("still fail after 3 rounds"), std::string::npos) << c.error;
      near += c.failing_slabs <= 1;
    }
    mapped_clean += c.flipped == 0;
  }
  ASSERT_GT(near, 0);
  ASSERT_EQ(mapped_clean, 0);
  tight.near_miss_slabs = 1;
  const Alignment second = choose_alignment(model, TopologyOptions{}, PolycubeOptions{}, tight);
  int rebuilt = 0;
  for (size_t i = 0; i < first.candidates.size(); ++i) {
    const AlignmentCandidate &a = first.candidates[i], &b = second.candidates[i];
    if (a.name.find("finer P") != std::string::npos) break;  // the variants follow the orientations
    EXPECT_EQ(a.name, b.name);
    if (a.corners >= 0) {
      EXPECT_EQ(b.corners, a.corners) << a.name;
      EXPECT_FALSE(b.fallback_budget) << a.name;
    } else if (a.failing_slabs == 1) {
      EXPECT_TRUE(b.corners >= 0 || !b.error.empty()) << a.name;
      if (b.corners >= 0) {
        ++rebuilt;
        EXPECT_TRUE(b.fallback_budget) << a.name;
        EXPECT_GE(b.flipped, 0) << a.name << " was not mapped";
      }
    } else {
      EXPECT_LT(b.corners, 0) << a.name << " was built again";
      EXPECT_EQ(b.error, a.error) << a.name;
    }
  }
  EXPECT_GT(rebuilt, 0);
}

}  // namespace
}  // namespace polycube
