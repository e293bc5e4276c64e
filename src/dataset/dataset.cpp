// Dataset::open: detect the layout, read the calibration (or the override), list each selected camera's
// images, assemble rig frames, read the ground truth. Dataset::loadImages reads one rig frame's images.
#include <filesystem>

#include "dataset_layout.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/dataset/image_file.hpp"
#include "mcslam/dataset/rig_frame_sync.hpp"

namespace mcslam {

namespace fs = std::filesystem;

namespace detail {

std::unique_ptr<DatasetLayout> detectLayout(const std::string& dir) {
  const fs::path d(dir);
  if (!fs::exists(d)) throw InputError(dir + ": no such folder");
  if (!fs::is_directory(d)) throw InputError(dir + ": not a folder (expected a dataset folder)");
  if (fs::is_directory(d / "mav0")) return makeEurocLayout((d / "mav0").string());
  const bool has_camchain = fs::exists(d / "camchain.yaml");
  if (!has_camchain && (d.filename() == "mav0" || fs::exists(d / "cam0" / "sensor.yaml"))) return makeEurocLayout(dir);
  if (fs::exists(d / "calib.txt") && fs::is_directory(d / "image_0")) return makeKittiLayout(dir);
  if (fs::is_directory(d / "image_00")) {
    const std::optional<std::string> calib = findKittiRawCalibration(dir);
    if (!calib) throw InputError(dir + ": KITTI raw images (image_00/) but no calib_cam_to_cam.txt here or above");
    return makeKittiRawLayout(dir, *calib);
  }
  if (has_camchain || fs::exists(d / "cam0" / "data.csv")) return makeAslLayout(dir);
  throw InputError(dir +
                   ": not a dataset folder: expected camchain.yaml and camN/data.csv (ASL), mav0/ (EuRoC), "
                   "calib.txt, times.txt and image_0/ (KITTI odometry) or image_00/ and calib_cam_to_cam.txt (KITTI "
                   "raw)");
}

}  // namespace detail

class DatasetBuilder {
 public:
  static Dataset open(const std::string& dir, const DatasetOptions& options) {
    const std::unique_ptr<detail::DatasetLayout> layout = detail::detectLayout(dir);
    Dataset ds;
    ds.dir_ = dir;
    ds.format_ = layout->format();
    const Rig full =
        options.calibration_override.empty() ? layout->loadRig() : loadRigFromPath(options.calibration_override);

    std::vector<int> selected = options.cameras;
    if (selected.empty()) {
      for (int c = 0; c < full.size(); ++c) selected.push_back(c);
    }
    ds.rig_ = full.subset(selected);  // validates the indices; keeps the full rig's body frame

    std::vector<std::vector<CameraImage>> images;
    for (int c : selected) images.push_back(layout->listImages(c, ds.warnings_));
    ds.sync_tolerance_ns_ = options.sync_tolerance_ns > 0 ? options.sync_tolerance_ns : layout->syncTolerance(images);
    ds.frames_ = assembleRigFrames(images, ds.sync_tolerance_ns_);
    noteIncompleteFrames(ds);

    if (!options.ground_truth_path.empty()) {
      ds.ground_truth_ = layout->readGroundTruthFile(options.ground_truth_path, full);
      ds.ground_truth_path_ = options.ground_truth_path;
    } else {
      try {
        ds.ground_truth_ = layout->loadGroundTruth(full, ds.warnings_, &ds.ground_truth_path_);
      } catch (const InputError& e) {
        ds.ground_truth_problem_ = e.what();
        ds.ground_truth_path_.clear();
        ds.warnings_.push_back(std::string("ground truth ignored: ") + e.what());
      }
    }
    return ds;
  }

 private:
  // One line that says how many frames lack a camera, so that a wrong tolerance or a dropped stream shows.
  static void noteIncompleteFrames(Dataset& ds) {
    std::size_t incomplete = 0;
    for (const RigFrameEntry& f : ds.frames_) {
      for (const std::string& p : f.image_paths) {
        if (p.empty()) {
          ++incomplete;
          break;
        }
      }
    }
    if (incomplete > 0) {
      ds.warnings_.push_back(ds.dir_ + ": " + std::to_string(incomplete) + " of " + std::to_string(ds.frames_.size()) +
                             " rig frames lack at least one camera (sync tolerance " +
                             std::to_string(ds.sync_tolerance_ns_ / 1000) + " us)");
    }
  }
};

Dataset Dataset::open(const std::string& dir, const DatasetOptions& options) {
  return DatasetBuilder::open(dir, options);
}

int Dataset::loadImages(std::size_t i, std::vector<Image>& images, std::vector<bool>& present,
                        std::string* error) const {
  const int n = rig_.size();
  if (static_cast<int>(images.size()) < n) images.resize(n);
  present.assign(n, false);
  if (error) error->clear();
  const auto report = [&](const std::string& message) {
    if (!error) return;
    if (!error->empty()) *error += "; ";
    *error += message;
  };
  if (i >= frames_.size()) {
    report(dir_ + ": frame " + std::to_string(i) + " does not exist (" + std::to_string(frames_.size()) + " frames)");
    return 0;
  }
  int loaded = 0;
  const RigFrameEntry& frame = frames_[i];
  for (int c = 0; c < n; ++c) {
    const std::string& path = frame.image_paths[c];
    if (path.empty()) continue;
    Image& img = images[c];
    const CameraModel& m = rig_.model(c);
    try {
      // Binary PGM: no allocation once img has the size. Nothing larger than the camera is decoded.
      readGreyImageFile(path, img, ImageBound{m.width(), m.height()});
    } catch (const InputError& e) {
      report(std::string(e.what()) + "; " + rig_.cameras[c].name + " left out");
      continue;
    }
    if (img.width() != m.width() || img.height() != m.height()) {
      report(path + ": image is " + std::to_string(img.width()) + "x" + std::to_string(img.height()) +
             " but the calibration of " + rig_.cameras[c].name + " says " + std::to_string(m.width()) + "x" +
             std::to_string(m.height()) + "; left out");
      continue;
    }
    present[c] = true;
    ++loaded;
  }
  return loaded;
}

Rig loadRigFromPath(const std::string& path) {
  const fs::path p(path);
  if (!fs::exists(p)) throw InputError(path + ": no such file or folder");
  if (fs::is_directory(p)) return detail::detectLayout(path)->loadRig();
  if (p.filename() == "calib.txt") return detail::makeKittiLayout(p.parent_path().string())->loadRig();
  const std::string text = readTextFile(path, kMaxConfigFileBytes);
  // EuRoC sensor.yaml has a top-level T_BS; Kalibr files have cam0, cam1, ...
  const bool euroc = text.rfind("T_BS:", 0) == 0 || text.find("\nT_BS:") != std::string::npos;
  return euroc ? loadEurocSensorRig({path}) : loadKalibrRig(path);
}

const Trajectory& Dataset::requireGroundTruth() const {
  if (ground_truth_) return *ground_truth_;
  if (!ground_truth_problem_.empty()) throw InputError(ground_truth_problem_);
  throw InputError(dir_ + ": the dataset has no ground truth");
}

}  // namespace mcslam
