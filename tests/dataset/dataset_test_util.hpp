#pragma once
// Builders for synthetic datasets written into temporary folders.
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "mcslam/calib/rig.hpp"
#include "mcslam/core/image.hpp"
#include "test_support.hpp"

namespace mcslam::test {

constexpr int kWidth = 16, kHeight = 12;

// n pinhole cameras of kWidth x kHeight, 0.1 m apart along x.
inline Rig smallRig(int n) {
  Rig rig;
  for (int c = 0; c < n; ++c) {
    RigCamera cam;
    cam.name = "cam" + std::to_string(c);
    cam.source_index = c;
    cam.model = CameraModel(kWidth, kHeight, 20, 20, 7.5, 5.5, Distortion::None);
    cam.T_b_c = SE3(Mat3::Identity(), Vec3(0.1 * c, 0, 0));
    rig.cameras.push_back(cam);
  }
  return rig;
}

// A grey image whose pixels all hold `value`.
struct FlatImage {
  Image image;
  explicit FlatImage(uint8_t value, int w = kWidth, int h = kHeight) : image(w, h) {
    std::fill(image.data(), image.data() + w * h, value);
  }
};

inline void writePng(const std::string& path, uint8_t value, int w = kWidth, int h = kHeight) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  cv::imwrite(path, cv::Mat(h, w, CV_8UC1, cv::Scalar(value)));
}

}  // namespace mcslam::test
