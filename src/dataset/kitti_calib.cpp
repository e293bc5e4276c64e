#include "kitti_calib.hpp"

#include <cmath>
#include <sstream>

#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"

namespace mcslam::detail {

namespace {

std::string trimmed(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// K [I | t]: upper triangular K with positive focal lengths and K(2,2) = 1.
bool isRectifiedProjection(const Mat34& P) {
  const Mat3 K = P.leftCols<3>();
  return K(0, 0) > 0 && K(1, 1) > 0 && std::abs(K(1, 0)) + std::abs(K(2, 0)) + std::abs(K(2, 1)) <= 1e-9 &&
         std::abs(K(2, 2) - 1.0) <= 1e-9;
}

// t of P = K [I | t].
Vec3 rectifiedOffset(const Mat34& P) { return P.leftCols<3>().triangularView<Eigen::Upper>().solve(P.col(3)); }

}  // namespace

KittiCalibFile::KittiCalibFile(std::string path) : path_(std::move(path)) {
  std::istringstream in(readTextFile(path_));
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;  // no entry (blank lines, comments)
    const std::string key = trimmed(line.substr(0, colon));
    const auto [it, added] = entries_.emplace(key, Entry{line_no, line.substr(colon + 1)});
    if (!added) {
      throw InputError(path_ + ": line " + std::to_string(line_no) + ": " + key + " is given twice (first on line " +
                       std::to_string(it->second.line) + ")");
    }
  }
}

std::string KittiCalibFile::where(const std::string& key) const {
  return path_ + ": line " + std::to_string(entries_.at(key).line) + ": " + key;
}

std::vector<double> KittiCalibFile::numbers(const std::string& key, std::size_t count,
                                            const std::string& meaning) const {
  std::istringstream ls(entries_.at(key).text);
  std::vector<double> v;
  std::string tok;
  while (ls >> tok) {
    char* end = nullptr;
    const double x = std::strtod(tok.c_str(), &end);
    if (end != tok.c_str() + tok.size() || !std::isfinite(x)) {
      throw InputError(where(key) + " entry is not a number: '" + tok + "'");
    }
    v.push_back(x);
  }
  if (v.size() != count) {
    throw InputError(where(key) + " must have " + std::to_string(count) + " numbers (" + meaning + "), got " +
                     std::to_string(v.size()));
  }
  return v;
}

Mat34 KittiCalibFile::rectifiedProjection(const std::string& key) const {
  const std::vector<double> v = numbers(key, 12, "a 3x4 projection matrix, row by row");
  Mat34 P;
  for (int k = 0; k < 12; ++k) P(k / 4, k % 4) = v[k];
  if (!isRectifiedProjection(P)) {
    throw InputError(
        where(key) +
        " is not a rectified projection K [I | t] (K upper triangular, positive focal lengths, K(2,2) = 1)");
  }
  return P;
}

RigCamera rectifiedCamera(int index, const Mat34& P, const Mat34& P0, int width, int height) {
  RigCamera c;
  c.name = "cam" + std::to_string(index);
  c.source_index = index;
  c.model = CameraModel(width, height, P(0, 0), P(1, 1), P(0, 2), P(1, 2), Distortion::None);
  c.T_b_c = SE3(Mat3::Identity(), rectifiedOffset(P0) - rectifiedOffset(P));
  return c;
}

}  // namespace mcslam::detail
