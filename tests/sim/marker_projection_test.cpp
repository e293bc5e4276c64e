// Rendered geometry against ground truth: small emissive square markers at known world points, seen by a distorted
// camera (ISEC radtan, TUM-VI equidistant fisheye) in a black void, are found as blobs in the image; each blob's
// centroid must lie where the ground-truth pose and the calibration project the marker centre, to 0.5 px.
//
// Blobs are found by thresholding and flood fill, without looking at the expected positions, and matched to the
// nearest projection, so a renderer that distorts wrongly (or not at all) fails here: the test also checks that an
// undistorted pinhole with the same intrinsics misses the blobs by several pixels.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/sim/renderer.hpp"
#include "mcslam/sim/rig_presets.hpp"
#include "mcslam/sim/world.hpp"
#include "test_support.hpp"

namespace mcslam::sim {
namespace {

struct Blob {
  double x = 0, y = 0;  // centroid weighted by linear intensity
  int pixels = 0;
};

// 4-connected components of non-black pixels. Weights undo the gamma so partial coverage counts linearly.
std::vector<Blob> findBlobs(const Image& image) {
  const int W = image.width(), H = image.height();
  std::vector<uint8_t> seen(static_cast<std::size_t>(W) * H, 0);
  std::vector<Blob> blobs;
  std::vector<int> stack;
  for (int start = 0; start < W * H; ++start) {
    if (seen[start] || image.data()[start] == 0) continue;
    double sw = 0, sx = 0, sy = 0;
    Blob b;
    stack.assign(1, start);
    seen[start] = 1;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      const int x = i % W, y = i / W;
      const double w = std::pow(image.data()[i] / 255.0, 2.2);
      sw += w;
      sx += w * x;
      sy += w * y;
      ++b.pixels;
      const int next[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
      for (const auto& n : next) {
        if (n[0] < 0 || n[1] < 0 || n[0] >= W || n[1] >= H) continue;
        const int j = n[1] * W + n[0];
        if (!seen[j] && image.data()[j] != 0) {
          seen[j] = 1;
          stack.push_back(j);
        }
      }
    }
    b.x = sx / sw;
    b.y = sy / sw;
    blobs.push_back(b);
  }
  return blobs;
}

struct Scene {
  std::shared_ptr<const World> world;
  std::vector<Vec3> markers;  // world points (marker centres)
};

// Markers on a grid of image positions across the whole valid field of view, at depths between 1.5 and 4 m, each
// facing the camera centre and about `pixels` wide. Positions come from unproject only to spread them evenly; the
// ground truth is the 3-D point.
Scene markerScene(const CameraModel& cam, const SE3& T_w_c, double pixels) {
  WorldBuilder builder(3, "markers");
  builder.setAmbient(0, 0, 1);  // no light: a marker's radiance is its emission, the void is black
  builder.setSky(0, 0);
  builder.setExposure(1.0);
  const Material glow = Material::lamp(0.8);
  Scene scene;
  const int nx = 9, ny = 7, margin = 24;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const Vec2 uv(margin + (cam.width() - 1 - 2.0 * margin) * i / (nx - 1),
                    margin + (cam.height() - 1 - 2.0 * margin) * j / (ny - 1));
      Vec3 b, b1;
      if (!cam.unproject(uv, b) || !cam.unproject(uv + Vec2(1, 0), b1)) continue;
      const double depth = 1.5 + 2.5 * ((i * 7 + j * 3) % 11) / 10.0;
      const double width = pixels * std::acos(std::clamp(b.dot(b1), -1.0, 1.0)) * depth;
      const Vec3 p_w = T_w_c * (depth * b);
      const Vec3 towards_camera = (T_w_c.t - p_w).normalized();
      const Vec3 up = std::abs(towards_camera.z()) < 0.9 ? Vec3::UnitZ() : Vec3::UnitX();
      builder.addPanel(p_w, towards_camera, up, width, width, glow, glow, 1e-4);
      scene.markers.push_back(p_w);
    }
  }
  scene.world = builder.build();
  return scene;
}

struct Residuals {
  int found = 0;      // markers with a blob
  double max_px = 0;  // largest centroid - projection distance
};

// Projects every marker with `model` (at pose T_w_c) and pairs it with the nearest blob, one blob per marker.
Residuals compare(const std::vector<Blob>& blobs, const std::vector<Vec3>& markers, const CameraModel& model,
                  const SE3& T_w_c) {
  Residuals r;
  const SE3 T_c_w = T_w_c.inverse();
  std::vector<bool> used(blobs.size(), false);
  for (const Vec3& p : markers) {
    Vec2 uv;
    if (!model.project(T_c_w * p, uv)) {
      r.max_px = INFINITY;
      continue;
    }
    int best = -1;
    double best_d = INFINITY;
    for (std::size_t k = 0; k < blobs.size(); ++k) {
      const double d = std::hypot(blobs[k].x - uv.x(), blobs[k].y - uv.y());
      if (!used[k] && d < best_d) {
        best_d = d;
        best = static_cast<int>(k);
      }
    }
    if (best < 0) continue;
    used[best] = true;
    ++r.found;
    r.max_px = std::max(r.max_px, best_d);
  }
  return r;
}

void checkCamera(const CameraModel& model, const char* what) {
  Rig rig;
  rig.cameras.push_back(RigCamera{"cam0", model, SE3(), 0});
  // An arbitrary, non-axis-aligned camera pose.
  const Mat3 R = (Eigen::AngleAxisd(0.7, Vec3::UnitZ()) * Eigen::AngleAxisd(-1.9, Vec3::UnitX()) *
                  Eigen::AngleAxisd(0.2, Vec3::UnitY()))
                     .toRotationMatrix();
  const SE3 T_w_c(R, Vec3(1.0, -2.0, 1.3));
  const Scene scene = markerScene(model, T_w_c, 6.0);

  RenderOptions options;
  options.threads = 2;
  options.edge_samples = 64;  // coverage in 1/64 steps: the centroid is then exact to a few hundredths of a pixel
  options.sensor.noise = false;
  options.sensor.vignetting = false;
  options.sensor.exposure_variation = false;
  Renderer renderer(scene.world, rig, options);
  Image image;
  renderer.render(0, T_w_c, 0.0, 0, image);
  const std::vector<Blob> blobs = findBlobs(image);

  ASSERT_GE(scene.markers.size(), 50u) << what;
  EXPECT_EQ(blobs.size(), scene.markers.size()) << what << ": every marker shows as one blob";
  const Residuals truth = compare(blobs, scene.markers, model, T_w_c);
  EXPECT_EQ(truth.found, static_cast<int>(scene.markers.size())) << what;
  EXPECT_LT(truth.max_px, 0.5) << what << ": rendered marker centroids vs ground-truth projection";
  ::testing::Test::RecordProperty(std::string(what) + "_max_px", std::to_string(truth.max_px));

  // The check can fail: the same intrinsics without distortion put the markers several pixels off.
  const CameraModel pinhole(model.width(), model.height(), model.fx(), model.fy(), model.cx(), model.cy(),
                            Distortion::None);
  const Residuals wrong = compare(blobs, scene.markers, pinhole, T_w_c);
  EXPECT_GT(wrong.max_px, 5.0) << what << ": the markers do not discriminate distortion models";
}

TEST(SimMarkers, RadtanIsecCameraProjectsMarkersWhereGroundTruthSays) {
  checkCamera(makePresetRig("isec").model(0), "isec cam0 radtan");
}

TEST(SimMarkers, EquidistantTumviCameraProjectsMarkersWhereGroundTruthSays) {
  const Rig tumvi = loadKalibrRig(test::dataPath("calib/tumvi_kalibr_imucam_chain.yaml"));
  ASSERT_EQ(tumvi.model(0).distortion(), Distortion::Equidistant);
  checkCamera(tumvi.model(0), "tumvi cam0 equidistant");
}

}  // namespace
}  // namespace mcslam::sim
