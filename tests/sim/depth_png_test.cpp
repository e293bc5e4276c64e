// Depth: the rendered depth agrees with the world's own ray caster (an independent path from the renderer's packet
// tracer), and the 16-bit PNGs exportDataset writes hold that depth in millimetres.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "mcslam/sim/dataset_export.hpp"
#include "mcslam/sim/simulation.hpp"
#include "test_support.hpp"

namespace mcslam::sim {
namespace {

class SimDepth : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SimulationConfig cfg;
    cfg.rig = "stereo";
    cfg.world = "corridor";
    cfg.frames = 2;
    sim_ = new Simulation(cfg);
  }
  static void TearDownTestSuite() {
    delete sim_;
    sim_ = nullptr;
  }
  static Simulation* sim_;
};
Simulation* SimDepth::sim_ = nullptr;

TEST_F(SimDepth, RenderedDepthMatchesTheWorldRayCaster) {
  Image image;
  DepthImage depth;
  const int frame = 1, cam = 1;
  sim_->render(frame, cam, image, &depth);
  const SE3 T_w_c = sim_->cameraPose(frame, cam);
  const CameraModel& model = sim_->rig().model(cam);
  int checked = 0, agree = 0, surfaces = 0;
  for (int y = 3; y < model.height(); y += 7) {
    for (int x = 5; x < model.width(); x += 7) {
      Vec3 b;
      if (!model.unproject(Vec2(x, y), b)) continue;
      const auto hit = sim_->world().intersect(T_w_c.t, T_w_c.R * b, 1e9, sim_->frameTime(frame));
      const double expected = hit ? hit->t * b.z() : 0.0;  // along the optical axis
      ++checked;
      surfaces += hit ? 1 : 0;
      if (std::abs(depth.at(x, y) - expected) < 1e-3 * std::max(1.0, expected)) ++agree;
    }
  }
  ASSERT_GT(checked, 5000);
  EXPECT_GT(surfaces, checked * 9 / 10) << "indoors nearly every pixel sees a surface";
  // Float rays against double ones may pick the other face exactly on a silhouette: allow a few such pixels.
  EXPECT_GE(agree, checked - checked / 500) << agree << " of " << checked << " pixels agree";
}

TEST_F(SimDepth, DepthPngHoldsRenderedDepthInMillimetres) {
  test::TempDir tmp("mcslam-sim-depth");
  ExportOptions options;
  options.cameras = {1};
  exportDataset(*sim_, tmp.path().string(), options);

  Image image;
  DepthImage depth;
  const int frame = 1;
  sim_->render(frame, 1, image, &depth);
  const auto png = tmp.path() / "cam0" / "depth" / (std::to_string(sim_->frameStamp(frame)) + ".png");
  ASSERT_TRUE(std::filesystem::exists(png)) << png;
  const cv::Mat mm = cv::imread(png.string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(mm.type(), CV_16UC1);
  ASSERT_EQ(mm.cols, depth.width);
  ASSERT_EQ(mm.rows, depth.height);
  int surfaces = 0;
  for (int y = 0; y < mm.rows; ++y) {
    for (int x = 0; x < mm.cols; ++x) {
      const double metres = depth.at(x, y);
      const int written = mm.at<uint16_t>(y, x);
      if (metres > 0 && metres * 1000 < 65535) {
        ++surfaces;
        ASSERT_LE(std::abs(written - metres * 1000.0), 0.5 + 1e-3) << "pixel " << x << "," << y;
      } else {
        ASSERT_EQ(written, 0) << "pixel " << x << "," << y << ": no surface or out of range must read 0";
      }
    }
  }
  EXPECT_GT(surfaces, mm.rows * mm.cols / 2);
}

}  // namespace
}  // namespace mcslam::sim
