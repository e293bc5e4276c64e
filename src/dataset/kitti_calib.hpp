#pragma once
// Internal: KITTI's calibration text files ("KEY: v1 v2 ...", one entry a line): the odometry benchmark's
// calib.txt and the raw recordings' calib_cam_to_cam.txt. Entries are kept as text and converted when used, so
// that entries no reader needs (calib_time, corner_dist, ...) never stop a run and a malformed one is reported
// with its file, line, key and value.
#include <map>
#include <string>
#include <vector>

#include "mcslam/calib/rig.hpp"

namespace mcslam::detail {

using Mat34 = Eigen::Matrix<double, 3, 4>;

class KittiCalibFile {
 public:
  // Reads the file; InputError when it cannot be read or a key is given twice.
  explicit KittiCalibFile(std::string path);
  const std::string& path() const { return path_; }
  bool has(const std::string& key) const { return entries_.count(key) > 0; }
  // "<path>: line <n>: <key>" for messages (the key must exist).
  std::string where(const std::string& key) const;
  // The entry's `count` numbers; InputError naming the value that is not a finite number or the count found.
  // `meaning` says what the numbers are, for the message.
  std::vector<double> numbers(const std::string& key, std::size_t count, const std::string& meaning) const;
  // A rectified camera's projection K [I | t]; InputError when it has another form.
  Mat34 rectifiedProjection(const std::string& key) const;

 private:
  struct Entry {
    int line = 0;
    std::string text;
  };
  std::string path_;
  std::map<std::string, Entry> entries_;
};

// Rectified cameras share one orientation; P = K [I | t] projects a point x given in the reference camera's
// frame as K (x + t), so the camera sits at -t there. The camera of projection P in a rig whose body frame is
// the camera of projection P0 (both rectified together).
RigCamera rectifiedCamera(int index, const Mat34& P, const Mat34& P0, int width, int height);

}  // namespace mcslam::detail
