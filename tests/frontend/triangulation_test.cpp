#include <gtest/gtest.h>

#include <random>

#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/geometry/triangulation.hpp"
#include "synthetic_rigs.hpp"

using namespace mcslam;

namespace {
std::vector<TriangulationObservation> observe(const Rig& rig, const Vec3& p_b, double noise_px, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, noise_px);
  std::vector<TriangulationObservation> obs;
  for (int c = 0; c < rig.size(); ++c) {
    Vec2 uv;
    if (!rig.model(c).project(rig.T_b_c(c).inverse() * p_b, uv) || !rig.model(c).inImage(uv)) continue;
    TriangulationObservation o;
    o.model = &rig.model(c);
    o.T_f_c = rig.T_b_c(c);
    o.uv = uv + Vec2(n(rng), n(rng));
    EXPECT_TRUE(o.model->unproject(o.uv, o.bearing));
    o.sigma_px = std::max(noise_px, 0.1);
    obs.push_back(o);
  }
  return obs;
}
}  // namespace

TEST(Triangulation, ExactRaysGiveTheExactPoint) {
  const Rig rig = test::isecRig();
  std::mt19937 rng(3);
  for (const Vec3& p : {Vec3(0.3, 0.1, 2.0), Vec3(-0.5, 0.3, 6.0), Vec3(1.0, -0.2, 12.0)}) {
    const auto obs = observe(rig, p, 0.0, rng);
    ASSERT_GE(obs.size(), 2u);
    const TriangulationResult r = triangulate(obs.data(), static_cast<int>(obs.size()), TriangulationOptions{});
    EXPECT_EQ(r.status, TriangulationStatus::Ok) << triangulationStatusName(r.status);
    EXPECT_LT((r.point - p).norm(), 1e-9 * p.norm());
  }
}

TEST(Triangulation, UncertaintyTellsFarPointsFromNearOnes) {
  const Rig rig = test::isecRig().subset({0, 1});  // 16.5 cm stereo
  std::mt19937 rng(4);
  TriangulationOptions opt;
  opt.max_relative_depth_sigma = 0.01;
  const auto near = observe(rig, Vec3(0.1, 0.0, 1.5), 0.3, rng);
  const auto far = observe(rig, Vec3(0.1, 0.0, 40.0), 0.3, rng);
  const TriangulationResult rn = triangulate(near.data(), static_cast<int>(near.size()), opt);
  const TriangulationResult rf = triangulate(far.data(), static_cast<int>(far.size()), opt);
  EXPECT_EQ(rn.status, TriangulationStatus::Ok);
  EXPECT_LT(std::abs(rn.point.z() - 1.5) / 1.5, 0.01);
  EXPECT_NE(rf.status, TriangulationStatus::Ok);                     // 40 m on 16.5 cm is not metric
  EXPECT_GT(rf.relative_depth_sigma, rn.relative_depth_sigma * 10);  // grows with depth (x27 here)
}

TEST(Triangulation, RejectsParallelAndInconsistentRays) {
  const Rig rig = test::isecRig();
  std::mt19937 rng(5);
  auto obs = observe(rig, Vec3(0.2, 0.1, 3.0), 0.0, rng);
  ASSERT_GE(obs.size(), 3u);
  obs[1].uv += Vec2(25.0, 0.0);  // a wrong match
  obs[1].model->unproject(obs[1].uv, obs[1].bearing);
  const TriangulationResult bad = triangulate(obs.data(), static_cast<int>(obs.size()), TriangulationOptions{});
  EXPECT_EQ(bad.status, TriangulationStatus::LargeReprojection);

  TriangulationObservation same[2] = {obs[0], obs[0]};  // identical rays
  EXPECT_EQ(triangulate(same, 2, TriangulationOptions{}).status, TriangulationStatus::Degenerate);
  EXPECT_EQ(triangulate(same, 1, TriangulationOptions{}).status, TriangulationStatus::TooFewRays);
}

TEST(Triangulation, DoesNotAllocate) {
  const Rig rig = test::isecRig();
  std::mt19937 rng(6);
  const auto obs = observe(rig, Vec3(0.2, 0.1, 3.0), 0.2, rng);
  alloc::ThreadScope scope;
  const TriangulationResult r = triangulate(obs.data(), static_cast<int>(obs.size()), TriangulationOptions{});
  EXPECT_EQ(scope.count(), 0u);
  EXPECT_TRUE(r.ok());
}

// Two views 10 cm apart, 1 px noise, points 2-10 m: a bound on sigma(depth)/depth keeps the points that noise put
// nearer (their inverse depth comes out too large on average); the same bound on sigma(1/depth) against the
// scene's inverse depth keeps the inverse-depth error centred. A monocular map is rebuilt from such points at
// every corner: the bias compounds into a map that shrinks (OdometrySynthetic.OneCameraKeepsItsUnitAroundCorners).
TEST(Triangulation, SceneReferenceKeepsTheInverseDepthUnbiased) {
  Rig rig = test::isecRig().subset({2});
  rig.cameras[0].T_b_c = SE3();
  rig.cameras.push_back(rig.cameras[0]);
  rig.cameras[1].T_b_c = SE3(Eigen::AngleAxisd(4.8 * M_PI / 180.0, Vec3::UnitY()).toRotationMatrix(), Vec3(0.1, 0, 0));
  const CameraModel& m = rig.model(0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  TriangulationOptions own;
  own.max_relative_depth_sigma = 0.15;  // the odometry's bound for new points
  TriangulationOptions scene = own;
  scene.reference_inverse_depth = 1.0 / 4.0;  // the median of depths uniform in 2-10 m is 6 m; a nearer scene
  double bias_own = 0, bias_scene = 0, sq_scene = 0;
  int kept_own = 0, kept_scene = 0;
  for (int i = 0; i < 20000; ++i) {
    Vec3 b;
    ASSERT_TRUE(m.unproject(Vec2(u(rng) * m.width(), u(rng) * m.height()), b));
    const Vec3 p = b / b.z() * (2.0 + 8.0 * u(rng));
    const auto obs = observe(rig, p, 1.0, rng);
    if (obs.size() != 2u) continue;
    const TriangulationResult ro = triangulate(obs.data(), 2, own);
    const TriangulationResult rs = triangulate(obs.data(), 2, scene);
    if (ro.ok()) {
      bias_own += 1.0 / ro.point.z() - 1.0 / p.z();
      ++kept_own;
    }
    if (rs.ok()) {
      const double e = 1.0 / rs.point.z() - 1.0 / p.z();
      bias_scene += e;
      sq_scene += e * e;
      ++kept_scene;
    }
  }
  ASSERT_GT(kept_own, 1000);
  ASSERT_GT(kept_scene, 1000);
  bias_own /= kept_own;
  bias_scene /= kept_scene;
  const double standard_error = std::sqrt(sq_scene / kept_scene / kept_scene);
  std::printf("kept %d / %d; mean inverse-depth error own %.5f scene %.5f (standard error %.5f) 1/m\n", kept_own,
              kept_scene, bias_own, bias_scene, standard_error);
  EXPECT_GT(bias_own, 5.0 * standard_error);  // too near on average
  EXPECT_LT(std::abs(bias_scene), 3.0 * standard_error);
}
