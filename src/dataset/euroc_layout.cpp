// The EuRoC MAV layout: mav0/camN/{sensor.yaml,data.csv,data/}, mav0/state_groundtruth_estimate0/data.csv.
// EuRoC's ground truth is the pose of its body (IMU) frame S in the world, T_w_S; ours is cam0's body frame:
// T_w_b = T_w_S * T_S_b = T_w_S * inverse(rig.T_b_imu).
#include <charconv>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "dataset_layout.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"

namespace mcslam::detail {

namespace fs = std::filesystem;

namespace {

// state_groundtruth_estimate0/data.csv: timestamp [ns], p_RS_R x y z [m], q_RS w x y z, then velocities and
// biases (ignored). Returns T_w_S.
Trajectory readEurocGroundTruthCsv(const std::string& path) {
  std::istringstream in(readTextFile(path));
  Trajectory traj;
  std::string line;
  int line_no = 0;
  static const char* kNames[8] = {"timestamp", "p_RS_R_x", "p_RS_R_y", "p_RS_R_z",
                                  "q_RS_w",    "q_RS_x",   "q_RS_y",   "q_RS_z"};
  while (std::getline(in, line)) {
    ++line_no;
    const std::string where = path + ": line " + std::to_string(line_no);
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) {
      const auto a = f.find_first_not_of(" \t\r"), b = f.find_last_not_of(" \t\r");
      fields.push_back(a == std::string::npos ? std::string() : f.substr(a, b - a + 1));
    }
    if (fields.size() < 8) {
      throw InputError(where + ": expected at least 8 values 'timestamp, p_RS_R x y z, q_RS w x y z', got " +
                       std::to_string(fields.size()));
    }
    StampedPose p;
    const std::string& stamp = fields[0];
    const auto [end, ec] = std::from_chars(stamp.data(), stamp.data() + stamp.size(), p.t);
    if (stamp.empty() || ec != std::errc() || end != stamp.data() + stamp.size()) {
      throw InputError(where + ": timestamp is not a whole number of nanoseconds: '" + stamp + "'");
    }
    double v[8];
    for (int k = 1; k < 8; ++k) {
      char* e = nullptr;
      v[k] = std::strtod(fields[k].c_str(), &e);
      if (fields[k].empty() || e != fields[k].c_str() + fields[k].size() || !std::isfinite(v[k])) {
        throw InputError(where + ": " + kNames[k] + " is not a number: '" + fields[k] + "'");
      }
    }
    const Eigen::Quaterniond q(v[4], v[5], v[6], v[7]);
    if (std::abs(q.norm() - 1.0) > 1e-2) {
      throw InputError(where + ": quaternion q_RS (w x y z) is not of unit length (norm " + std::to_string(q.norm()) +
                       ")");
    }
    p.T_w_b = SE3(q, Vec3(v[1], v[2], v[3]));
    traj.push_back(p);
  }
  return traj;
}

Trajectory toBodyFrame(Trajectory traj, const Rig& rig, const std::string& path) {
  if (!rig.T_b_imu) {
    throw InputError(path +
                     ": EuRoC ground truth is the IMU pose, but the calibration gives no camera-IMU transform "
                     "(T_BS / T_cam_imu) to bring it into the body frame");
  }
  const SE3 T_imu_b = rig.T_b_imu->inverse();
  for (StampedPose& p : traj) p.T_w_b = p.T_w_b * T_imu_b;
  return traj;
}

class EurocLayout : public DatasetLayout {
 public:
  explicit EurocLayout(std::string mav0) : root_(std::move(mav0)) {}
  const char* format() const override { return "euroc"; }
  const std::string& root() const override { return root_; }

  Rig loadRig() const override {
    std::vector<std::string> sensors;
    for (int c = 0;; ++c) {
      const fs::path s = fs::path(root_) / ("cam" + std::to_string(c)) / "sensor.yaml";
      if (!fs::exists(s)) break;
      sensors.push_back(s.string());
    }
    if (sensors.empty()) throw InputError(root_ + ": no cam0/sensor.yaml (EuRoC camera calibration)");
    return loadEurocSensorRig(sensors);
  }

  std::vector<CameraImage> listImages(int cam, std::vector<std::string>& warnings) const override {
    return readAslImageList((fs::path(root_) / ("cam" + std::to_string(cam))).string(), warnings);
  }

  std::optional<Trajectory> loadGroundTruth(const Rig& rig, std::vector<std::string>& warnings,
                                            std::string* source) const override {
    const fs::path gt = fs::path(root_) / "state_groundtruth_estimate0" / "data.csv";
    if (!fs::exists(gt)) return std::nullopt;
    if (!rig.T_b_imu) {
      warnings.push_back(gt.string() +
                         ": ground truth left out: the calibration gives no camera-IMU transform to "
                         "bring the IMU poses into the body frame");
      return std::nullopt;
    }
    *source = gt.string();
    return toBodyFrame(readEurocGroundTruthCsv(gt.string()), rig, gt.string());
  }

  // A .csv is read as EuRoC ground truth (IMU poses, converted); anything else as TUM body poses.
  Trajectory readGroundTruthFile(const std::string& path, const Rig& rig) const override {
    if (fs::path(path).extension() == ".csv") return toBodyFrame(readEurocGroundTruthCsv(path), rig, path);
    return readTumTrajectory(path);
  }

 private:
  std::string root_;
};

}  // namespace

std::unique_ptr<DatasetLayout> makeEurocLayout(const std::string& mav0) { return std::make_unique<EurocLayout>(mav0); }

}  // namespace mcslam::detail
