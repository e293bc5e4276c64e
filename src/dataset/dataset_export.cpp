// Dataset export: shared parts (output folder, image placement, ground truth per frame) and the ASL and
// EuRoC writers; the KITTI writer is in kitti_export.cpp.
#include "dataset_export_detail.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/image_file.hpp"
#include "mcslam/dataset/rig_frame_sync.hpp"

namespace mcslam {

namespace fs = std::filesystem;

DatasetLayoutKind parseDatasetLayout(const std::string& name) {
  if (name == "asl") return DatasetLayoutKind::Asl;
  if (name == "euroc") return DatasetLayoutKind::Euroc;
  if (name == "kitti") return DatasetLayoutKind::Kitti;
  throw InputError("unknown dataset layout '" + name + "' (supported: asl, euroc, kitti)");
}

ExportImages parseExportImages(const std::string& name) {
  if (name == "original") return ExportImages::Original;
  if (name == "pgm") return ExportImages::Pgm;
  throw InputError("unknown image format '" + name + "' (supported: original, pgm)");
}

const char* datasetLayoutName(DatasetLayoutKind kind) {
  switch (kind) {
    case DatasetLayoutKind::Asl: return "asl";
    case DatasetLayoutKind::Euroc: return "euroc";
    case DatasetLayoutKind::Kitti: return "kitti";
  }
  return "?";
}

namespace detail {

void prepareOutputFolder(const std::string& dir) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !(fs::is_directory(dir, ec) && fs::is_empty(dir, ec))) {
    throw InputError(dir + ": already exists and is not an empty folder (choose a new output folder)");
  }
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create folder: " + ec.message());
}

void createFolder(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir.string() + ": cannot create folder: " + ec.message());
}

void writeTextFile(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.flush();
  if (!out) throw InputError(path.string() + ": cannot write file");
}

// A hard link keeps the bytes and costs no space; across file systems (or where links are refused) a copy.
void placeImage(const std::string& source, const fs::path& target, bool must_be_png) {
  std::string ext = fs::path(source).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (must_be_png && ext != ".png") {
    const cv::Mat grey = cv::imread(source, cv::IMREAD_GRAYSCALE);
    if (grey.empty()) throw InputError(source + ": cannot read image");
    if (!cv::imwrite(target.string(), grey)) throw InputError(target.string() + ": cannot write image");
    return;
  }
  std::error_code ec;
  fs::create_hard_link(source, target, ec);
  if (!ec) return;
  fs::copy_file(source, target, ec);
  if (ec) throw InputError(target.string() + ": cannot copy " + source + ": " + ec.message());
}

std::vector<std::optional<SE3>> groundTruthPerFrame(const Dataset& dataset) {
  std::vector<std::optional<SE3>> out(dataset.size());
  if (!dataset.groundTruth()) return out;
  const Trajectory& gt = *dataset.groundTruth();
  const Timestamp tol = std::max<Timestamp>(dataset.syncToleranceNs(), 1000);
  for (std::size_t i = 0; i < dataset.size(); ++i) {
    const Timestamp t = dataset.frames()[i].t;
    const auto it =
        std::lower_bound(gt.begin(), gt.end(), t, [](const StampedPose& p, Timestamp s) { return p.t < s; });
    const StampedPose* best = nullptr;
    if (it != gt.end()) best = &*it;
    if (it != gt.begin() && (!best || t - std::prev(it)->t < best->t - t)) best = &*std::prev(it);
    if (best && std::abs(best->t - t) <= tol) out[i] = best->T_w_b;
  }
  return out;
}

namespace {

// The images of every camera over all rig frames, each stamped with its rig frame's time: the cameras' own stamps
// may lie further apart than the reader of the written layout groups (KITTI raw's colour cameras stamp ~6 ms
// before the grey ones), and the written dataset must hold the rig frames that were read.
std::vector<std::vector<CameraImage>> imagesPerCamera(const Dataset& dataset) {
  std::vector<std::vector<CameraImage>> out(dataset.rig().size());
  for (const RigFrameEntry& f : dataset.frames()) {
    for (int c = 0; c < dataset.rig().size(); ++c) {
      if (!f.image_paths[c].empty()) out[c].push_back({f.t, f.image_paths[c]});
    }
  }
  return out;
}

// camN/data.csv and camN/data/<ns>.<ext> of every camera (ASL and EuRoC share this part); returns the images
// written, per camera.
std::vector<std::vector<CameraImage>> writeAslCameras(const Dataset& dataset, const fs::path& root,
                                                      const DatasetExportOptions& options,
                                                      DatasetExportReport& report) {
  auto images = imagesPerCamera(dataset);
  const bool pgm = options.images == ExportImages::Pgm;
  Image pixels;  // reused for every image re-written as PGM
  for (int c = 0; c < dataset.rig().size(); ++c) {
    const fs::path cam = root / ("cam" + std::to_string(c));
    createFolder(cam / "data");
    std::string csv = "#timestamp [ns],filename\n";
    for (const CameraImage& im : images[c]) {
      const std::string name =
          std::to_string(im.t) + (pgm ? std::string(".pgm") : fs::path(im.path).extension().string());
      if (pgm) {
        readGreyImageFile(im.path, pixels);
        writePgmFile((cam / "data" / name).string(), pixels.view());
      } else {
        placeImage(im.path, cam / "data" / name, false);
      }
      csv += std::to_string(im.t) + "," + name + "\n";
      ++report.images_written;
    }
    writeTextFile(cam / "data.csv", csv);
  }
  report.frames_written = dataset.size();
  return images;
}

// Median period of one camera's images, in Hz (EuRoC's rate_hz); 0 when it cannot be told.
double cameraRateHz(const std::vector<CameraImage>& images) {
  if (images.size() < 2) return 0.0;
  std::vector<Timestamp> dt;
  for (std::size_t i = 1; i < images.size(); ++i) dt.push_back(images[i].t - images[i - 1].t);
  std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
  return dt[dt.size() / 2] > 0 ? 1e9 / static_cast<double>(dt[dt.size() / 2]) : 0.0;
}

std::string eurocSensorYaml(const CameraModel& m, const SE3& T_B_c, double rate_hz, int cam) {
  std::ostringstream os;
  os.precision(17);
  const Mat4 T = T_B_c.matrix();
  os << "%YAML:1.0\n# Written by mcslam-dataset convert.\nsensor_type: camera\ncomment: cam" << cam << "\n\n";
  os << "# Sensor extrinsics wrt. the body-frame.\nT_BS:\n  cols: 4\n  rows: 4\n  data: [";
  for (int k = 0; k < 16; ++k) os << (k ? ", " : "") << T(k / 4, k % 4);
  os << "]\n\n# Camera specific definitions.\nrate_hz: " << rate_hz << "\n";
  os << "resolution: [" << m.width() << ", " << m.height() << "]\ncamera_model: pinhole\n";
  os << "intrinsics: [" << m.fx() << ", " << m.fy() << ", " << m.cx() << ", " << m.cy() << "] #fu, fv, cu, cv\n";
  // No distortion is radial-tangential with zero coefficients: what EuRoC readers expect.
  os << "distortion_model: " << (m.distortion() == Distortion::Equidistant ? "equidistant" : "radial-tangential")
     << "\n";
  const auto& k = m.coeffs();
  os << "distortion_coefficients: [" << k[0] << ", " << k[1] << ", " << k[2] << ", " << k[3] << "]\n";
  return os.str();
}

void exportAsl(const Dataset& dataset, const fs::path& root, const DatasetExportOptions& options,
               DatasetExportReport& report) {
  const Rig& rig = dataset.rig();
  const SE3 T_b_c0 = rig.T_b_c(0);
  Rig out = rig;
  out.rebase(T_b_c0.inverse());  // the written camchain's body is its cam0
  writeKalibrRig(out, (root / "camchain.yaml").string());
  writeAslCameras(dataset, root, options, report);
  if (!dataset.groundTruth()) return;
  Trajectory gt = *dataset.groundTruth();
  for (StampedPose& p : gt) p.T_w_b = p.T_w_b * T_b_c0;
  writeTumTrajectory((root / "groundtruth.txt").string(), gt);
  report.ground_truth_poses = gt.size();
}

void exportEuroc(const Dataset& dataset, const fs::path& root, const DatasetExportOptions& options,
                 DatasetExportReport& report) {
  const Rig& rig = dataset.rig();
  const fs::path mav0 = root / "mav0";
  const auto images = writeAslCameras(dataset, mav0, options, report);
  // EuRoC's body frame B: the IMU when the calibration has one, else the first written camera.
  const SE3 T_b_B = rig.T_b_imu ? *rig.T_b_imu : rig.T_b_c(0);
  for (int c = 0; c < rig.size(); ++c) {
    writeTextFile(mav0 / ("cam" + std::to_string(c)) / "sensor.yaml",
                  eurocSensorYaml(rig.model(c), T_b_B.inverse() * rig.T_b_c(c), cameraRateHz(images[c]), c));
  }
  if (!dataset.groundTruth()) return;
  std::string csv =
      "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z []\n";
  char buf[256];
  for (const StampedPose& p : *dataset.groundTruth()) {
    const SE3 T_w_B = p.T_w_b * T_b_B;
    const Eigen::Quaterniond q = T_w_B.quaternion();
    std::snprintf(buf, sizeof(buf), "%lld,%.9f,%.9f,%.9f,%.12f,%.12f,%.12f,%.12f\n", static_cast<long long>(p.t),
                  T_w_B.t.x(), T_w_B.t.y(), T_w_B.t.z(), q.w(), q.x(), q.y(), q.z());
    csv += buf;
  }
  createFolder(mav0 / "state_groundtruth_estimate0");
  writeTextFile(mav0 / "state_groundtruth_estimate0" / "data.csv", csv);
  report.ground_truth_poses = dataset.groundTruth()->size();
}

}  // namespace
}  // namespace detail

DatasetExportReport exportDataset(const Dataset& dataset, DatasetLayoutKind layout, const std::string& out_dir,
                                  const DatasetExportOptions& options) {
  DatasetExportReport report;
  if (layout == DatasetLayoutKind::Kitti) {  // refused before anything is written
    if (options.images != ExportImages::Original)
      throw InputError(out_dir +
                       ": the KITTI layout holds PNG images only (image_N/000000.png); PGM images are for "
                       "the asl and euroc layouts");
    detail::checkKittiRig(dataset.rig());
  }
  detail::prepareOutputFolder(out_dir);
  switch (layout) {
    case DatasetLayoutKind::Asl: detail::exportAsl(dataset, out_dir, options, report); break;
    case DatasetLayoutKind::Euroc: detail::exportEuroc(dataset, out_dir, options, report); break;
    case DatasetLayoutKind::Kitti: detail::exportKitti(dataset, out_dir, report); break;
  }
  return report;
}

}  // namespace mcslam
