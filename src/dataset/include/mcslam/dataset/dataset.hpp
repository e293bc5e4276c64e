#pragma once
// Recorded multi-camera datasets, read as rig frames.
//
// Formats (detected from the folder):
//  - native ASL layout (as Kalibr and EuRoC use it): camchain.yaml, camN/data.csv
//    ("#timestamp [ns],filename"), camN/data/<ns>.png, optional groundtruth.txt (TUM, seconds,
//    pose of the body in the world).
//  - EuRoC: mav0/camN/{sensor.yaml,data.csv,data/}, mav0/state_groundtruth_estimate0/data.csv
//    (IMU poses, converted into our body frame = cam0).
//  - KITTI odometry: image_0/, image_1/ (and image_2/, image_3/) PNG, calib.txt (P0..P3), times.txt, optional
//    poses file (cam0 poses): poses.txt in the folder, ../../poses/<sequence>.txt, or given in the options.
//  - KITTI raw (synced+rectified drive): image_00/ .. image_03/ with data/<index>.png and timestamps.txt,
//    calib_cam_to_cam.txt (P_rect_0N, S_rect_0N) in the drive folder or the date folder above it; body frame =
//    rectified camera 0; colour images read as grey; no ground truth.
// Images of different cameras are assembled into rig frames by timestamp within a tolerance; a camera
// without an image at some time gives a rig frame without that camera, never a shifted pairing.
#include <optional>
#include <string>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/core/image.hpp"
#include "mcslam/dataset/trajectory.hpp"

namespace mcslam {

struct RigFrameEntry {
  Timestamp t = 0;                       // rig frame time (the earliest camera stamp of the frame)
  std::vector<std::string> image_paths;  // one per camera of the rig; empty when that camera has none
  std::vector<Timestamp> camera_stamps;  // one per camera; 0 when absent (a present stamp may be 0 too, e.g.
                                         // KITTI's first frame: test image_paths for presence)
};

struct DatasetOptions {
  // Calibration to use instead of the dataset's own (anything loadRigFromPath reads); its camera i reads
  // the dataset's camera i (camN/, image_N/).
  std::string calibration_override;
  // Cameras to keep, by calibration index (empty = all). The body frame stays the full rig's.
  std::vector<int> cameras;
  // Largest difference between stamps of one rig frame; 0 = automatic (a third of the shortest per-camera
  // median frame period, at most 5 ms).
  Timestamp sync_tolerance_ns = 0;
  // Ground truth file to use instead of the dataset's own: TUM (body pose in the world) for ASL and EuRoC,
  // KITTI poses (cam0, times from times.txt) for KITTI; for EuRoC a .csv is read as EuRoC ground truth (IMU).
  std::string ground_truth_path;
};

class Dataset {
 public:
  // Throws InputError naming the folder and the missing or malformed file.
  static Dataset open(const std::string& dir, const DatasetOptions& options = {});

  const std::string& format() const { return format_; }  // "asl", "euroc", "kitti" or "kitti_raw"
  const std::string& directory() const { return dir_; }
  const Rig& rig() const { return rig_; }
  const std::vector<RigFrameEntry>& frames() const { return frames_; }
  std::size_t size() const { return frames_.size(); }
  // Ground truth in our body frame, when the dataset has it.
  const std::optional<Trajectory>& groundTruth() const { return ground_truth_; }
  // The file the ground truth came from (empty without ground truth).
  const std::string& groundTruthPath() const { return ground_truth_path_; }
  // The ground truth, or InputError naming the dataset and why it has none: no file, or what was wrong with the
  // dataset's own file, kept from open() (a run that does not need the ground truth is not stopped by a bad one;
  // it gets a warning).
  const Trajectory& requireGroundTruth() const;
  // The tolerance used to assemble rig frames (the option, or the automatic choice).
  Timestamp syncToleranceNs() const { return sync_tolerance_ns_; }
  // Problems met while indexing (e.g. a camera listing a missing file); the frames stay usable.
  const std::vector<std::string>& warnings() const { return warnings_; }

  // Loads the grey images of rig frame i into `images` (one per camera; an Image only reallocates when it
  // grows). present[c] tells which cameras have an image. An unreadable image is reported in *error and its
  // camera marked absent; returns the number of images loaded.
  int loadImages(std::size_t i, std::vector<Image>& images, std::vector<bool>& present, std::string* error) const;

 private:
  std::string dir_;
  std::string format_;
  Rig rig_;
  std::vector<RigFrameEntry> frames_;
  std::optional<Trajectory> ground_truth_;
  std::string ground_truth_path_;
  std::string ground_truth_problem_;
  Timestamp sync_tolerance_ns_ = 0;
  std::vector<std::string> warnings_;
  friend class DatasetBuilder;
};

// A rig from any calibration source: a Kalibr camchain YAML, an EuRoC sensor.yaml (one camera), a KITTI
// calib.txt, or a dataset folder (its own calibration, as Dataset::open reads it). Throws InputError.
Rig loadRigFromPath(const std::string& path);

// Writes a dataset in the native ASL layout (what mcslam-sim produces).
class AslDatasetWriter {
 public:
  // Creates dir (and camN/data/), writes camchain.yaml. Throws InputError when it cannot.
  AslDatasetWriter(const std::string& dir, const Rig& rig);
  // Writes camN/data/<t>.png and appends to camN/data.csv.
  void writeImage(int cam, Timestamp t, const ImageView& image);
  // Writes groundtruth.txt (TUM).
  void writeGroundTruth(const Trajectory& gt);
  // Flushes the csv files.
  void close();
  ~AslDatasetWriter();

 private:
  std::string dir_;
  int cameras_ = 0;
  std::vector<std::string> csv_rows_;  // per camera, flushed on close()
  bool closed_ = false;
};

}  // namespace mcslam
