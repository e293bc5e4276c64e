#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"

namespace mcslam {

namespace fs = std::filesystem;

AslDatasetWriter::AslDatasetWriter(const std::string& dir, const Rig& rig) : dir_(dir), cameras_(rig.size()) {
  std::error_code ec;
  for (int c = 0; c < cameras_; ++c) {
    fs::create_directories(fs::path(dir) / ("cam" + std::to_string(c)) / "data", ec);
    if (ec) throw InputError(dir + ": cannot create folder: " + ec.message());
  }
  writeKalibrRig(rig, (fs::path(dir) / "camchain.yaml").string());
  csv_rows_.assign(cameras_, "#timestamp [ns],filename\n");
}

void AslDatasetWriter::writeImage(int cam, Timestamp t, const ImageView& image) {
  if (cam < 0 || cam >= cameras_) throw InputError(dir_ + ": camera " + std::to_string(cam) + " is not in the rig");
  const std::string name = std::to_string(t) + ".png";
  const fs::path path = fs::path(dir_) / ("cam" + std::to_string(cam)) / "data" / name;
  const cv::Mat mat(image.height, image.width, CV_8UC1, const_cast<uint8_t*>(image.data), image.stride);
  if (!cv::imwrite(path.string(), mat)) throw InputError(path.string() + ": cannot write image");
  csv_rows_[cam] += std::to_string(t) + "," + name + "\n";
}

void AslDatasetWriter::writeGroundTruth(const Trajectory& gt) {
  writeTumTrajectory((fs::path(dir_) / "groundtruth.txt").string(), gt);
}

void AslDatasetWriter::close() {
  if (closed_) return;
  for (int c = 0; c < cameras_; ++c) {
    const fs::path path = fs::path(dir_) / ("cam" + std::to_string(c)) / "data.csv";
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << csv_rows_[c];
    out.flush();  // a full disk shows only when the buffer goes out
    if (!out) throw InputError(path.string() + ": write failed");
  }
  closed_ = true;
}

AslDatasetWriter::~AslDatasetWriter() {
  try {
    close();
  } catch (...) {
    // Destructors must not throw; close() explicitly to see the error.
  }
}

}  // namespace mcslam
