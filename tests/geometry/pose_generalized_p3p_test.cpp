#include <gtest/gtest.h>

#include <opengv/absolute_pose/CentralAbsoluteAdapter.hpp>
#include <opengv/absolute_pose/NoncentralAbsoluteAdapter.hpp>
#include <opengv/absolute_pose/methods.hpp>

#include "mcslam/geometry/generalized_p3p.hpp"
#include "mcslam/geometry/generalized_p3p_roots.hpp"
#include "pose_scenes.hpp"

using namespace mcslam;
using namespace mcslam::test;

namespace {

struct P3PProblem {
  SE3 T_w_b;
  std::array<BodyRay, 3> rays;
  std::array<Vec3, 3> points;
  std::array<int, 3> cams;
  std::array<Vec3, 3> bearings_c;
};

// Three noise-free correspondences from random cameras of the rig.
P3PProblem randomProblem(const Rig& rig, SceneRandom& r) {
  P3PProblem p;
  p.T_w_b = r.pose(5.0);
  for (int i = 0; i < 3; ++i) {
    p.cams[i] = r.index(rig.size());
    p.points[i] = pointSeenBy(rig, p.cams[i], p.T_w_b, r, 1.0, 30.0);
    p.bearings_c[i] = (rig.T_b_c(p.cams[i]).inverse() * (p.T_w_b.inverse() * p.points[i])).normalized();
    p.rays[i] = bodyRay(rig, p.cams[i], p.bearings_c[i]);
  }
  return p;
}

bool poseClose(const SE3& a, const SE3& b, double tol) {
  return rotationAngle(a.R, b.R) < tol && (a.t - b.t).norm() < tol;
}

// Largest angle between a ray and the direction from its origin to its point under T_w_b
// (infinite for a non-finite pose: OpenGV's solvers sometimes return NaN).
double worstRayAngle(const P3PProblem& p, const SE3& T_w_b) {
  if (!T_w_b.R.allFinite() || !T_w_b.t.allFinite()) return INFINITY;
  double worst = 0;
  for (int i = 0; i < 3; ++i) {
    const Vec3 v = T_w_b.inverse() * p.points[i] - p.rays[i].origin;
    worst = std::max(worst, std::atan2(v.cross(p.rays[i].direction).norm(), v.dot(p.rays[i].direction)));
  }
  return worst;
}

opengv::transformations_t openGvGp3p(const Rig& rig, const P3PProblem& p) {
  opengv::bearingVectors_t bearings(p.bearings_c.begin(), p.bearings_c.end());
  std::vector<int> cams(p.cams.begin(), p.cams.end());
  opengv::points_t points(p.points.begin(), p.points.end());
  opengv::translations_t offsets;
  opengv::rotations_t rotations;
  for (const RigCamera& c : rig.cameras) {
    offsets.push_back(c.T_b_c.t);
    rotations.push_back(c.T_b_c.R);
  }
  opengv::absolute_pose::NoncentralAbsoluteAdapter adapter(bearings, cams, points, offsets, rotations);
  return opengv::absolute_pose::gp3p(adapter, 0, 1, 2);
}

}  // namespace

TEST(PolynomialRoots, FindsSimpleAndDoubleRootsInTheInterval) {
  // (x - 1)(x + 3)(x - 0.5)^2 (x - 7) = expanded by hand below via repeated multiplication.
  std::vector<double> p{1.0};
  auto times = [&](double root) {
    std::vector<double> q(p.size() + 1, 0.0);
    for (size_t i = 0; i < p.size(); ++i) {
      q[i + 1] += p[i];
      q[i] -= root * p[i];
    }
    p = q;
  };
  for (double r : {1.0, -3.0, 0.5, 0.5, 7.0}) times(r);
  double roots[kMaxPolynomialDegree];
  const int n = realPolynomialRoots(p.data(), 5, -10, 10, roots);
  ASSERT_EQ(n, 4);
  const double expected[] = {-3.0, 0.5, 1.0, 7.0};
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(roots[i], expected[i], 1e-7) << i;
  // Only the part of the interval asked for.
  EXPECT_EQ(realPolynomialRoots(p.data(), 5, 0.75, 5, roots), 1);
  EXPECT_NEAR(roots[0], 1.0, 1e-12);
  // x^2 + 1 has no real root; the zero polynomial reports none.
  const double no_real[] = {1.0, 0.0, 1.0};
  EXPECT_EQ(realPolynomialRoots(no_real, 2, -10, 10, roots), 0);
  const double zero[] = {0.0, 0.0, 0.0};
  EXPECT_EQ(realPolynomialRoots(zero, 2, -10, 10, roots), 0);
}

// Every rig shape, noise-free: the true pose is among the solutions to 1e-9, and every solution
// puts the three points on their rays.
TEST(GeneralizedP3P, RecoversTruePoseOnEveryRigShape) {
  for (const NamedRig& shape : allRigShapes()) {
    SceneRandom r(11);
    int found = 0, total_solutions = 0;
    const int trials = 400;
    for (int t = 0; t < trials; ++t) {
      const P3PProblem p = randomProblem(shape.rig, r);
      GeneralizedP3PSolutions sol;
      const int n = solveGeneralizedP3P(p.rays, p.points, sol);
      total_solutions += n;
      bool hit = false;
      for (int s = 0; s < n; ++s) {
        hit = hit || poseClose(sol.T_w_b[s], p.T_w_b, 1e-9);
        EXPECT_LT(worstRayAngle(p, sol.T_w_b[s]), 1e-6) << shape.name;
        EXPECT_NEAR(sol.T_w_b[s].R.determinant(), 1.0, 1e-12);
      }
      found += hit ? 1 : 0;
    }
    EXPECT_EQ(found, trials) << shape.name;
    EXPECT_LE(total_solutions, 8 * trials);
  }
}

// Non-central rigs: every pose OpenGV's gp3p (Kneip, Groebner basis) returns that really satisfies
// the rays, with the points in front, is also among ours; and each of ours that OpenGV finds
// accurately enough to compare, OpenGV finds too. OpenGV's solver is far less accurate (its
// residuals spread from 1e-12 to failures), so the comparison uses the verified subset.
TEST(GeneralizedP3P, AgreesWithOpenGvGp3p) {
  for (const NamedRig& shape : allRigShapes()) {
    if (shape.rig.size() == 1) continue;  // OpenGV's gp3p assumes non-central rays
    SceneRandom r(23);
    int theirs_valid = 0, theirs_valid_in_ours = 0, ours_total = 0, ours_in_theirs = 0;
    for (int t = 0; t < 200; ++t) {
      const P3PProblem p = randomProblem(shape.rig, r);
      GeneralizedP3PSolutions sol;
      const int n = solveGeneralizedP3P(p.rays, p.points, sol);
      const opengv::transformations_t theirs = openGvGp3p(shape.rig, p);
      for (const auto& T : theirs) {
        const SE3 pose(T.leftCols<3>(), T.col(3));
        if (worstRayAngle(p, pose) > 1e-7) continue;  // inaccurate or behind a camera
        ++theirs_valid;
        bool match = false;
        for (int s = 0; s < n; ++s) match = match || poseClose(sol.T_w_b[s], pose, 1e-5);
        theirs_valid_in_ours += match ? 1 : 0;
      }
      for (int s = 0; s < n; ++s) {
        ++ours_total;
        bool match = false;
        for (const auto& T : theirs) match = match || poseClose(sol.T_w_b[s], SE3(T.leftCols<3>(), T.col(3)), 1e-3);
        ours_in_theirs += match ? 1 : 0;
      }
    }
    std::printf("[%s] OpenGV's verified solutions found by us: %d/%d; ours found by OpenGV (1e-3): %d/%d\n",
                shape.name.c_str(), theirs_valid_in_ours, theirs_valid, ours_in_theirs, ours_total);
    EXPECT_GT(theirs_valid, 100) << shape.name;
    EXPECT_EQ(theirs_valid_in_ours, theirs_valid) << shape.name;
    EXPECT_GE(ours_in_theirs, ours_total * 85 / 100) << shape.name;
  }
}

// One camera (offset from the body): the same solutions as OpenGV's central P3P (Kneip), whose
// camera poses we map to the body with the extrinsic.
TEST(GeneralizedP3P, CentralCaseAgreesWithOpenGvP3P) {
  const Rig rig = monoRig();
  const SE3 T_c_b = rig.T_b_c(0).inverse();
  SceneRandom r(31);
  int theirs_valid = 0, theirs_valid_in_ours = 0;
  for (int t = 0; t < 200; ++t) {
    const P3PProblem p = randomProblem(rig, r);
    GeneralizedP3PSolutions sol;
    const int n = solveGeneralizedP3P(p.rays, p.points, sol);
    opengv::bearingVectors_t bearings(p.bearings_c.begin(), p.bearings_c.end());
    opengv::points_t points(p.points.begin(), p.points.end());
    opengv::absolute_pose::CentralAbsoluteAdapter adapter(bearings, points);
    for (const auto& T : opengv::absolute_pose::p3p_kneip(adapter, 0, 1, 2)) {
      const SE3 T_w_b = SE3(T.leftCols<3>(), T.col(3)) * T_c_b;
      if (worstRayAngle(p, T_w_b) > 1e-7) continue;
      ++theirs_valid;
      bool match = false;
      for (int s = 0; s < n; ++s) match = match || poseClose(sol.T_w_b[s], T_w_b, 1e-6);
      theirs_valid_in_ours += match ? 1 : 0;
    }
  }
  EXPECT_GT(theirs_valid, 200);
  EXPECT_EQ(theirs_valid_in_ours, theirs_valid);
}

TEST(GeneralizedP3P, PluckerRaysSolveWithAnyCheirality) {
  const Rig rig = ringRig();
  SceneRandom r(5);
  for (int t = 0; t < 100; ++t) {
    P3PProblem p = randomProblem(rig, r);
    std::array<BodyRay, 3> lines;
    for (int i = 0; i < 3; ++i) lines[i] = bodyRayFromPlucker(rig.ray(p.cams[i], p.bearings_c[i]));
    GeneralizedP3PSolutions sol;
    const int n = solveGeneralizedP3P(lines, p.points, sol, Cheirality::Any);
    bool hit = false;
    for (int s = 0; s < n; ++s) hit = hit || poseClose(sol.T_w_b[s], p.T_w_b, 1e-9);
    EXPECT_TRUE(hit) << t;
  }
}

// Degenerate input gives no solution, and nearly degenerate input gives only verified poses.
TEST(GeneralizedP3P, DegenerateInputGivesNoGarbage) {
  const Rig rig = stereoRig();
  SceneRandom r(3);
  for (int t = 0; t < 50; ++t) {
    P3PProblem p = randomProblem(rig, r);
    GeneralizedP3PSolutions sol;
    // Collinear world points.
    std::array<Vec3, 3> collinear{p.points[0], p.points[1], 0.3 * p.points[0] + 0.7 * p.points[1]};
    EXPECT_EQ(solveGeneralizedP3P(p.rays, collinear, sol), 0);
    // Coincident points.
    std::array<Vec3, 3> same{p.points[0], p.points[0], p.points[0]};
    EXPECT_EQ(solveGeneralizedP3P(p.rays, same, sol), 0);
    // Zero direction.
    std::array<BodyRay, 3> bad = p.rays;
    bad[1].direction = Vec3::Zero();
    EXPECT_EQ(solveGeneralizedP3P(bad, p.points, sol), 0);
    // Nearly collinear world points: whatever comes back must satisfy the rays.
    const Vec3 off = (p.points[1] - p.points[0]).cross(Vec3::UnitZ()).normalized() * 1e-5;
    P3PProblem q = p;
    q.points[2] = 0.5 * (p.points[0] + p.points[1]) + off;
    for (int i = 0; i < 3; ++i) {
      q.bearings_c[i] = (rig.T_b_c(q.cams[i]).inverse() * (q.T_w_b.inverse() * q.points[i])).normalized();
      q.rays[i] = bodyRay(rig, q.cams[i], q.bearings_c[i]);
    }
    const int n = solveGeneralizedP3P(q.rays, q.points, sol);
    for (int s = 0; s < n; ++s) EXPECT_LT(worstRayAngle(q, sol.T_w_b[s]), 1e-6);
    // Two identical rays (two points on one line): only poses that satisfy all three rays.
    P3PProblem d = p;
    d.rays[1] = d.rays[0];
    const int m = solveGeneralizedP3P(d.rays, d.points, sol);
    for (int s = 0; s < m; ++s) EXPECT_LT(worstRayAngle(d, sol.T_w_b[s]), 1e-6);
  }
}
