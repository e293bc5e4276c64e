#pragma once
// Internal: one implementation per dataset layout (ASL, EuRoC, KITTI odometry, KITTI raw). Dataset::open detects the
// layout, then works through this interface: calibration, per-camera image lists, ground truth.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <unordered_set>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/dataset/rig_frame_sync.hpp"
#include "mcslam/dataset/trajectory.hpp"

namespace mcslam::detail {

class DatasetLayout {
 public:
  virtual ~DatasetLayout() = default;
  virtual const char* format() const = 0;
  // The folder holding the data (mav0/ for EuRoC).
  virtual const std::string& root() const = 0;
  // The dataset's own calibration. Throws InputError.
  virtual Rig loadRig() const = 0;
  // Images of camera `cam` (index in the full calibration), sorted by time with unique stamps. Listed files that
  // do not exist are left out with a warning. Throws InputError when the list itself is missing or malformed.
  virtual std::vector<CameraImage> listImages(int cam, std::vector<std::string>& warnings) const = 0;
  // The dataset's ground truth in the body frame of `rig` (the full rig in use), if it has one; sets *source.
  virtual std::optional<Trajectory> loadGroundTruth(const Rig& rig, std::vector<std::string>& warnings,
                                                    std::string* source) const = 0;
  // A ground truth file named by the user, in this layout's format, in the body frame of `rig`.
  virtual Trajectory readGroundTruthFile(const std::string& path, const Rig& rig) const {
    return readTumTrajectory(path);
  }
  // The tolerance that assembles rig frames from these images when the options give none.
  virtual Timestamp syncTolerance(const std::vector<std::vector<CameraImage>>& images) const {
    return automaticSyncTolerance(images);
  }
};

// Throws InputError naming the folder when it is no dataset this reader knows.
std::unique_ptr<DatasetLayout> detectLayout(const std::string& dir);

std::unique_ptr<DatasetLayout> makeAslLayout(const std::string& root);
std::unique_ptr<DatasetLayout> makeEurocLayout(const std::string& mav0);
std::unique_ptr<DatasetLayout> makeKittiLayout(const std::string& root);
std::unique_ptr<DatasetLayout> makeKittiRawLayout(const std::string& root, const std::string& calibration);

// A KITTI raw drive's calib_cam_to_cam.txt: in the folder or in the (date) folder above it.
std::optional<std::string> findKittiRawCalibration(const std::string& dir);

// camN/data.csv ("#timestamp [ns],filename") of an ASL or EuRoC camera folder -> images under camN/data/.
std::vector<CameraImage> readAslImageList(const std::string& camera_dir, std::vector<std::string>& warnings);

// The names of the files in `dir` (none when it cannot be read).
std::unordered_set<std::string> fileNames(const std::filesystem::path& dir);

// The images of camera `cam` in `dir` named by their index (`name(i)`), one for each of `times` (read from
// `times_path`, which messages name by line): a missing one is a warning, times that do not increase an InputError.
std::vector<CameraImage> indexedImages(const std::filesystem::path& dir, int cam, const std::vector<Timestamp>& times,
                                       const std::string& times_path, std::string (*name)(std::size_t),
                                       std::vector<std::string>& warnings);

// Collects "listed but missing" warnings for one camera, summarising after the first few.
class MissingImageReport {
 public:
  MissingImageReport(std::string camera, std::vector<std::string>& warnings)
      : camera_(std::move(camera)), warnings_(warnings) {}
  void add(const std::string& where, const std::string& path);
  // Adds the summary line of what add() did not list.
  void finish();

 private:
  std::string camera_;
  std::vector<std::string>& warnings_;
  int count_ = 0;
};

}  // namespace mcslam::detail
