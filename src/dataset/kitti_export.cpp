// KITTI odometry layout writer: rectified cameras only (see dataset_export.hpp).
#include <cmath>
#include <cstdio>

#include "dataset_export_detail.hpp"
#include "mcslam/core/error.hpp"

namespace mcslam::detail {

namespace fs = std::filesystem;

void checkKittiRig(const Rig& rig) {
  if (rig.size() > 4) {
    throw InputError("KITTI layout holds at most 4 cameras (image_0..image_3); this rig has " +
                     std::to_string(rig.size()) + " (select some with --cameras)");
  }
  const Mat3& R0 = rig.T_b_c(0).R;
  for (int c = 0; c < rig.size(); ++c) {
    const CameraModel& m = rig.model(c);
    const auto& k = m.coeffs();
    if (m.distortion() != Distortion::None && (k[0] != 0 || k[1] != 0 || k[2] != 0 || k[3] != 0)) {
      throw InputError(rig.cameras[c].name + ": distortion " + distortionName(m.distortion()) +
                       " with non-zero coefficients: the KITTI layout holds rectified images only (no distortion)");
    }
    const double angle = Eigen::AngleAxisd(R0.transpose() * rig.T_b_c(c).R).angle();
    if (angle > 1e-6) {
      char buf[160];
      std::snprintf(buf, sizeof(buf),
                    ": turned %.4f deg from %s: the KITTI layout holds rectified cameras only (same orientation)",
                    angle * 180.0 / M_PI, rig.cameras[0].name.c_str());
      throw InputError(rig.cameras[c].name + buf);
    }
  }
}

namespace {

// P_k = K_k [I | t_k] with t_k = -(camera k's centre in cam0's frame): what KITTI's calib.txt gives.
std::string calibText(const Rig& rig) {
  std::string text;
  const SE3 T_c0_b = rig.T_b_c(0).inverse();
  for (int c = 0; c < rig.size(); ++c) {
    const CameraModel& m = rig.model(c);
    Mat3 K = Mat3::Identity();
    K(0, 0) = m.fx();
    K(1, 1) = m.fy();
    K(0, 2) = m.cx();
    K(1, 2) = m.cy();
    const Vec3 t = -(T_c0_b * rig.T_b_c(c).t);
    Eigen::Matrix<double, 3, 4> P;
    P.leftCols<3>() = K;
    P.col(3) = K * t;
    char buf[64];
    std::snprintf(buf, sizeof(buf), "P%d:", c);
    text += buf;
    for (int r = 0; r < 3; ++r) {
      for (int col = 0; col < 4; ++col) {
        std::snprintf(buf, sizeof(buf), " %.12e", P(r, col));
        text += buf;
      }
    }
    text += "\n";
  }
  return text;
}

}  // namespace

void exportKitti(const Dataset& dataset, const fs::path& root, DatasetExportReport& report) {
  const Rig& rig = dataset.rig();
  for (int c = 0; c < rig.size(); ++c) createFolder(root / ("image_" + std::to_string(c)));
  writeTextFile(root / "calib.txt", calibText(rig));
  const std::vector<std::optional<SE3>> gt = groundTruthPerFrame(dataset);
  const SE3& T_b_c0 = rig.T_b_c(0);
  std::string times;
  Trajectory poses;
  bool every_pose = true;
  for (std::size_t i = 0; i < dataset.size(); ++i) {
    const RigFrameEntry& f = dataset.frames()[i];
    bool complete = true;
    for (int c = 0; c < rig.size(); ++c) complete = complete && !f.image_paths[c].empty();
    if (!complete) {
      ++report.frames_skipped;
      continue;
    }
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", report.frames_written);
    for (int c = 0; c < rig.size(); ++c) {
      placeImage(f.image_paths[c], root / ("image_" + std::to_string(c)) / name, true);
      ++report.images_written;
    }
    times += toSecondsString(f.t) + "\n";
    if (gt[i]) poses.push_back({f.t, *gt[i] * T_b_c0});
    every_pose = every_pose && gt[i].has_value();
    ++report.frames_written;
  }
  writeTextFile(root / "times.txt", times);
  if (report.frames_skipped) {
    report.warnings.push_back(std::to_string(report.frames_skipped) +
                              " rig frames left out: a camera had no image (KITTI cannot mark an image missing)");
  }
  if (!dataset.groundTruth()) return;
  if (!every_pose || poses.empty()) {
    report.warnings.push_back("poses.txt not written: the ground truth (" + dataset.groundTruthPath() +
                              ") has no pose at the time of every written frame");
    return;
  }
  // KITTI's poses are cam0's, in the frame of the first one.
  const SE3 T_first_w = poses.front().T_w_b.inverse();
  for (StampedPose& p : poses) p.T_w_b = T_first_w * p.T_w_b;
  writeKittiTrajectory((root / "poses.txt").string(), poses);
  report.ground_truth_poses = poses.size();
}

}  // namespace mcslam::detail
