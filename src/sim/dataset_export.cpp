#include "mcslam/sim/dataset_export.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"

namespace mcslam::sim {

namespace fs = std::filesystem;

void writeDepthPng(const std::string& path, const DepthImage& depth) {
  cv::Mat mm(depth.height, depth.width, CV_16U);
  for (int y = 0; y < depth.height; ++y) {
    uint16_t* row = mm.ptr<uint16_t>(y);
    for (int x = 0; x < depth.width; ++x) {
      const double v = std::round(depth.at(x, y) * 1000.0);
      row[x] = v >= 1.0 && v <= 65535.0 ? static_cast<uint16_t>(v) : 0;
    }
  }
  if (!cv::imwrite(path, mm)) throw InputError(path + ": cannot write depth image");
}

ExportSummary exportDataset(Simulation& sim, const std::string& dir, const ExportOptions& options) {
  std::vector<int> cams = options.cameras;
  if (cams.empty()) {
    for (int c = 0; c < sim.rig().size(); ++c) cams.push_back(c);
  }
  // Written rig: the selected cameras with the first one as the body frame (as loadKalibrRig will read it).
  Rig written = sim.rig().subset(cams);
  const SE3 T_b_first = sim.rig().T_b_c(cams.front());
  written.rebase(T_b_first.inverse());
  written.T_b_imu.reset();

  AslDatasetWriter writer(dir, written);
  if (options.depth) {
    for (std::size_t k = 0; k < cams.size(); ++k) {
      std::error_code ec;
      fs::create_directories(fs::path(dir) / ("cam" + std::to_string(k)) / "depth", ec);
      if (ec) throw InputError(dir + ": cannot create depth folder: " + ec.message());
    }
  }
  Trajectory gt;
  Image image;
  DepthImage depth;
  const int n = sim.frameCount();
  for (int i = 0; i < n; ++i) {
    const Timestamp t = sim.frameStamp(i);
    for (std::size_t k = 0; k < cams.size(); ++k) {
      sim.render(i, cams[k], image, options.depth ? &depth : nullptr);
      writer.writeImage(static_cast<int>(k), t, image.view());
      if (options.depth) {
        writeDepthPng((fs::path(dir) / ("cam" + std::to_string(k)) / "depth" / (std::to_string(t) + ".png")).string(),
                      depth);
      }
    }
    gt.push_back({t, sim.bodyPose(i) * T_b_first});
    if (options.progress) options.progress(i + 1, n);
  }
  writer.writeGroundTruth(gt);
  writer.close();

  ExportSummary summary;
  summary.frames = n;
  summary.cameras = static_cast<int>(cams.size());
  summary.path_length = pathLength(gt);
  summary.duration = n > 1 ? toSeconds(gt.back().t - gt.front().t) : 0.0;

  const fs::path info = fs::path(dir) / "sim.yaml";
  std::ofstream out(info);
  out << "# written by mcslam-sim\n";
  if (!options.description.empty()) out << "description: \"" << options.description << "\"\n";
  out << "world: " << sim.world().name() << "\nseed: " << sim.world().seed() << "\ntrajectory: \""
      << sim.trajectory().description() << "\"\nrate_hz: " << sim.rate() << "\nframes: " << n << "\ncameras: [";
  for (std::size_t k = 0; k < cams.size(); ++k) out << (k ? ", " : "") << cams[k];
  out << "]\npath_length_m: " << summary.path_length << "\nduration_s: " << summary.duration << "\ndepth: "
      << (options.depth ? "camN/depth/<ns>.png, uint16 millimetres along the optical axis, 0 = none" : "none") << "\n";
  if (!out) throw InputError(info.string() + ": cannot write");
  return summary;
}

}  // namespace mcslam::sim
