#pragma once
// Reading and writing rig calibrations in the formats the field uses:
//  - Kalibr camchain / imu-camchain YAML (camN: camera_model, intrinsics, distortion_model,
//    distortion_coeffs, resolution, T_cn_cnm1, T_cam_imu or T_imu_cam), with or without the
//    "%YAML:1.0" first line OpenCV writes.
//  - EuRoC per-camera sensor.yaml (T_BS, intrinsics, distortion_coefficients, resolution).
// Every error names the file, the camera and the field.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "mcslam/calib/rig.hpp"

namespace mcslam {

// The most cameras a rig file may hold: multi-view features keep one bit per camera (track_builder), and the
// pipeline and the map file refuse more.
inline constexpr int kMaxRigCameras = 64;

struct RigLoadOptions {
  // Pose of cam0 in the desired body frame; identity (body = cam0) when absent.
  std::optional<SE3> T_body_cam0;
};

Rig loadKalibrRig(const std::string& path, const RigLoadOptions& options = {});
// Parses Kalibr YAML text; `source` names it in error messages.
Rig parseKalibrRig(const std::string& yaml_text, const std::string& source, const RigLoadOptions& options = {});

// One sensor.yaml per camera, in camera order. The EuRoC body (IMU) frame becomes T_b_imu.
Rig loadEurocSensorRig(const std::vector<std::string>& sensor_yaml_paths, const RigLoadOptions& options = {});

// Writes a Kalibr camchain (T_cn_cnm1 chain plus, when known, T_cam_imu) that loadKalibrRig reads back.
void writeKalibrRig(const Rig& rig, const std::string& path);
std::string formatKalibrRig(const Rig& rig);

// Reads a whole text file; throws InputError naming the path when it cannot or when it holds more than
// `max_bytes` (a device such as /dev/zero, or the wrong file, must not take the memory). The default bounds the data
// files (image lists, ground truth); configuration and calibration files are far smaller.
inline constexpr std::size_t kMaxDataFileBytes = std::size_t{1} << 30;
inline constexpr std::size_t kMaxConfigFileBytes = std::size_t{16} << 20;
std::string readTextFile(const std::string& path, std::size_t max_bytes = kMaxDataFileBytes);

}  // namespace mcslam
