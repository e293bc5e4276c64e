#pragma once
// Shared by the daemon tests: a tiny ASL dataset written with mcslam::AslDatasetWriter (PNG, or converted to
// PGM), and config text.
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/dataset/dataset_export.hpp"

namespace mcslam::test {

inline Rig smallRig(int cameras, int width, int height) {
  Rig rig;
  for (int c = 0; c < cameras; ++c) {
    RigCamera cam;
    cam.name = "cam" + std::to_string(c);
    cam.model = CameraModel(width, height, 0.8 * width, 0.8 * width, 0.5 * width, 0.5 * height, Distortion::None);
    const double yaw = 2.0 * M_PI * c / cameras;
    cam.T_b_c = SE3(so3Exp(Vec3(0, yaw, 0)), Vec3(0.1 * std::sin(yaw), 0, 0.1 * std::cos(yaw)));
    cam.source_index = c;
    rig.cameras.push_back(cam);
  }
  return rig;
}

// `frames` rig frames every `period_ns`, random (seeded) texture; returns the folder.
inline std::string writeSmallDataset(const std::string& dir, int cameras, int frames, int width = 64, int height = 48,
                                     Timestamp period_ns = 50000000) {
  AslDatasetWriter writer(dir, smallRig(cameras, width, height));
  std::mt19937 rng(7);
  Image img(width, height);
  for (int f = 0; f < frames; ++f)
    for (int c = 0; c < cameras; ++c) {
      for (int i = 0; i < width * height; ++i) img.data()[i] = static_cast<uint8_t>(rng());
      writer.writeImage(c, 1000000000000ll + f * period_ns, img.view());
    }
  writer.close();
  return dir;
}

// The same dataset with its images as binary PGM (what mcslam-dataset convert --images pgm writes), in `dir`; the
// PNG original goes to `dir`_png.
inline std::string writeSmallPgmDataset(const std::string& dir, int cameras, int frames, int width = 64,
                                        int height = 48) {
  const std::string png = writeSmallDataset(dir + "_png", cameras, frames, width, height);
  DatasetExportOptions options;
  options.images = ExportImages::Pgm;
  exportDataset(Dataset::open(png), DatasetLayoutKind::Asl, dir, options);
  return dir;
}

}  // namespace mcslam::test
