#include <gtest/gtest.h>

#include <random>

#include "mcslam/calib/calibration_io.hpp"
#include "test_support.hpp"

using namespace mcslam;

namespace {

std::vector<Rig> allSharedRigs() {
  std::vector<Rig> rigs;
  for (const char* f :
       {"isec_5cam_camchain.yaml", "euroc_kalibr_imucam_chain.yaml", "tumvi_kalibr_imucam_chain.yaml"}) {
    rigs.push_back(loadKalibrRig(test::dataPath(std::string("calib/") + f)));
  }
  rigs.push_back(loadEurocSensorRig(
      {test::dataPath("calib/euroc_cam0_sensor.yaml"), test::dataPath("calib/euroc_cam1_sensor.yaml")}));
  return rigs;
}

double roundTripError(const CameraModel& cam, const Vec2& uv) {
  Vec3 b;
  if (!cam.unproject(uv, b)) return 1e9;
  EXPECT_NEAR(b.norm(), 1.0, 1e-12);
  Vec2 back;
  if (!cam.project(b * 3.7, back)) return 1e9;
  return (back - uv).norm();
}

}  // namespace

// Every pixel of a dense grid, the image corners and borders included, for every shared calibration.
TEST(CameraModel, RoundTripBelowMicroPixelOverWholeImage) {
  for (const Rig& rig : allSharedRigs()) {
    for (const RigCamera& rc : rig.cameras) {
      const CameraModel& cam = rc.model;
      double worst = 0;
      for (int y = 0; y <= cam.height() - 1; y += 3) {
        for (int x = 0; x <= cam.width() - 1; x += 3) worst = std::max(worst, roundTripError(cam, Vec2(x, y)));
      }
      for (const Vec2& corner :
           {Vec2(0, 0), Vec2(cam.width() - 1, 0), Vec2(0, cam.height() - 1), Vec2(cam.width() - 1, cam.height() - 1),
            Vec2(-0.5, -0.5), Vec2(cam.width() - 0.5, cam.height() - 0.5)}) {
        worst = std::max(worst, roundTripError(cam, corner));
      }
      EXPECT_LT(worst, 1e-6) << rc.name << " " << distortionName(cam.distortion());
    }
  }
}

TEST(CameraModel, FisheyeCornersLieBeyondNinetyDegrees) {
  const Rig rig = loadKalibrRig(test::dataPath("calib/tumvi_kalibr_imucam_chain.yaml"));
  Vec3 b;
  ASSERT_TRUE(rig.model(0).unproject(Vec2(0, 0), b));
  EXPECT_LT(b.z(), 0.0);  // the TUM-VI lens sees behind its own image plane
}

TEST(CameraModel, ProjectionJacobianMatchesNumeric) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const Rig& rig : allSharedRigs()) {
    for (const RigCamera& rc : rig.cameras) {
      const CameraModel& cam = rc.model;
      for (int trial = 0; trial < 200; ++trial) {
        Vec3 b;
        ASSERT_TRUE(cam.unproject(Vec2(u(rng) * (cam.width() - 1), u(rng) * (cam.height() - 1)), b));
        const Vec3 p = b * (0.5 + 10 * u(rng));
        Vec2 uv;
        Mat23 J;
        ASSERT_TRUE(cam.project(p, uv, &J));
        for (int k = 0; k < 3; ++k) {
          const double h = 1e-6 * std::max(1.0, p.norm());
          Vec3 pp = p, pm = p;
          pp[k] += h;
          pm[k] -= h;
          Vec2 up, um;
          ASSERT_TRUE(cam.project(pp, up));
          ASSERT_TRUE(cam.project(pm, um));
          const Vec2 numeric = (up - um) / (2 * h);
          EXPECT_LT((numeric - J.col(k)).norm(), 1e-4 * std::max(1.0, J.col(k).norm())) << rc.name << " k=" << k;
        }
      }
    }
  }
}

TEST(CameraModel, RejectsPointsBehindOrOutsideTheValidDomain) {
  const Rig isec = loadKalibrRig(test::dataPath("calib/isec_5cam_camchain.yaml"));
  Vec2 uv;
  EXPECT_FALSE(isec.model(0).project(Vec3(0.1, 0.2, -1.0), uv));
  EXPECT_FALSE(isec.model(0).project(Vec3(0.1, 0.2, 0.0), uv));
  // A strongly barrel-distorted lens folds back beyond its turning point: we must refuse there.
  const CameraModel folding(640, 480, 400, 400, 320, 240, Distortion::RadTan, {-0.45, 0.0, 0.0, 0.0});
  EXPECT_TRUE(folding.project(Vec3(0.5, 0.0, 1.0), uv));
  EXPECT_FALSE(folding.project(Vec3(2.0, 0.0, 1.0), uv));
  EXPECT_LT(folding.maxValidAngle(), M_PI / 2);
}

TEST(CameraModel, PinholeMatchesTextbook) {
  const CameraModel cam(640, 480, 500, 510, 320, 240, Distortion::None);
  Vec2 uv;
  ASSERT_TRUE(cam.project(Vec3(0.2, -0.1, 2.0), uv));
  EXPECT_NEAR(uv.x(), 320 + 500 * 0.1, 1e-12);
  EXPECT_NEAR(uv.y(), 240 - 510 * 0.05, 1e-12);
}

TEST(Rig, PluckerRayContainsThePoint) {
  const Rig rig = loadKalibrRig(test::dataPath("calib/isec_5cam_camchain.yaml"));
  const Vec3 p_c(0.3, -0.2, 4.0);
  for (int c = 0; c < rig.size(); ++c) {
    const PluckerRay r = rig.ray(c, p_c.normalized());
    const Vec3 p_b = rig.T_b_c(c) * p_c;
    EXPECT_NEAR(r.d.norm(), 1.0, 1e-12);
    EXPECT_LT((p_b.cross(r.d) - r.m).norm(), 1e-12);  // a point x lies on (d, m) iff x × d = m
    EXPECT_NEAR(r.d.dot(r.m), 0.0, 1e-12);
  }
}
