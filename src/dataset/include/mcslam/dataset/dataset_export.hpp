#pragma once
// Writes an opened dataset in another layout, so that one recording (a rendered sequence, say) can be
// replayed by tools that read EuRoC or KITTI, and so that our own readers of those layouts can be checked
// against the native one on identical data.
//
//  - asl:   camchain.yaml (Kalibr), camN/data.csv + data/<ns>.<ext>, groundtruth.txt (TUM, body = cam0).
//  - euroc: mav0/camN/{sensor.yaml,data.csv,data/}, mav0/state_groundtruth_estimate0/data.csv. The EuRoC
//           body frame B is the calibration's IMU when it has one, else the first written camera.
//  - kitti: image_0/ .. image_3/ (<frame index>.png, six digits), calib.txt (P0..P3 = K [I | t]),
//           times.txt (seconds from the first frame), poses.txt (cam0 in the frame of the first cam0 pose).
//           Only rectified rigs: pinhole cameras without distortion, all with cam0's orientation, at most 4;
//           only rig frames with every camera present (KITTI has no way to say an image is missing).
// Images are hard-linked when the output is on the same file system, copied otherwise (bytes unchanged);
// KITTI's non-PNG sources are re-encoded to PNG (lossless, grey). With ExportImages::Pgm (ASL and EuRoC) every
// image is written as binary 8-bit PGM instead, which replays without the image codec module (image_file.hpp).
//
// Library mcslam_dataset_export (it links OpenCV imgcodecs, which mcslam_dataset does not).
#include <string>
#include <vector>

#include "mcslam/dataset/dataset.hpp"

namespace mcslam {

enum class DatasetLayoutKind { Asl, Euroc, Kitti };

// "asl", "euroc", "kitti" -> kind; throws InputError naming the text otherwise.
DatasetLayoutKind parseDatasetLayout(const std::string& name);
const char* datasetLayoutName(DatasetLayoutKind kind);

struct DatasetExportReport {
  std::size_t frames_written = 0;  // rig frames written (KITTI) or rig frames with at least one image written
  std::size_t images_written = 0;
  std::size_t frames_skipped = 0;  // KITTI: rig frames missing a camera
  std::size_t ground_truth_poses = 0;
  std::vector<std::string> warnings;  // e.g. ground truth not written because frames lack a pose
};

// How the images are written: Original = the files as they are (hard links or copies), Pgm = decoded and written
// as binary 8-bit PGM (<ns>.pgm; grey, lossless).
enum class ExportImages { Original, Pgm };

// "original", "pgm" -> kind; throws InputError naming the text otherwise.
ExportImages parseExportImages(const std::string& name);

struct DatasetExportOptions {
  ExportImages images = ExportImages::Original;
};

// Writes `dataset` (its cameras, as opened: a camera subset stays a subset) into `out_dir`, which must not
// exist or be empty. Throws InputError naming the folder, camera or field when the layout cannot hold the data
// (KITTI with ExportImages::Pgm: its images are PNG by definition).
DatasetExportReport exportDataset(const Dataset& dataset, DatasetLayoutKind layout, const std::string& out_dir,
                                  const DatasetExportOptions& options = {});

}  // namespace mcslam
