// The KITTI odometry layout: image_0/ .. image_3/ (<index>.png, six digits), calib.txt with the rectified
// 3x4 projection matrices P0..P3, times.txt (seconds), optional cam0 poses (KITTI format).
// P_k = K_k [I | t_k]: every rectified camera has cam0's orientation and sits at -t_k in cam0's frame (for the
// stereo pair t_1 = (P1(0,3) / fx, 0, 0), i.e. the baseline is P1(0,3) / -fx).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <unordered_set>

#include "dataset_layout.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/image_file.hpp"

namespace mcslam::detail {

namespace fs = std::filesystem;

namespace {

using Mat34 = Eigen::Matrix<double, 3, 4>;

std::map<std::string, Mat34> readProjections(const std::string& path) {
  std::map<std::string, Mat34> out;
  std::istringstream in(readTextFile(path));
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string key = line.substr(0, colon);
    key.erase(0, key.find_first_not_of(" \t"));
    if (key.size() != 2 || key[0] != 'P' || key[1] < '0' || key[1] > '3') continue;  // e.g. Tr: (velodyne)
    std::istringstream ls(line.substr(colon + 1));
    std::vector<double> v;
    std::string tok;
    while (ls >> tok) {
      char* end = nullptr;
      const double x = std::strtod(tok.c_str(), &end);
      if (end != tok.c_str() + tok.size() || !std::isfinite(x)) {
        throw InputError(path + ": line " + std::to_string(line_no) + ": " + key + " entry is not a number: '" + tok +
                         "'");
      }
      v.push_back(x);
    }
    if (v.size() != 12) {
      throw InputError(path + ": line " + std::to_string(line_no) + ": " + key +
                       " must have 12 numbers (a 3x4 projection matrix, row by row), got " + std::to_string(v.size()));
    }
    Mat34 P;
    for (int k = 0; k < 12; ++k) P(k / 4, k % 4) = v[k];
    const Mat3 K = P.leftCols<3>();
    if (!(K(0, 0) > 0 && K(1, 1) > 0) || std::abs(K(1, 0)) + std::abs(K(2, 0)) + std::abs(K(2, 1)) > 1e-9 ||
        std::abs(K(2, 2) - 1.0) > 1e-9) {
      throw InputError(
          path + ": line " + std::to_string(line_no) + ": " + key +
          " is not a rectified projection K [I | t] (K upper triangular, positive focal lengths, K(2,2) = 1)");
    }
    out[key] = P;
  }
  return out;
}

std::string imageName(std::size_t index) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%06zu.png", index);
  return buf;
}

class KittiLayout : public DatasetLayout {
 public:
  explicit KittiLayout(std::string root) : root_(std::move(root)) {}
  const char* format() const override { return "kitti"; }
  const std::string& root() const override { return root_; }

  Rig loadRig() const override {
    const std::string calib = (fs::path(root_) / "calib.txt").string();
    const std::map<std::string, Mat34> P = readProjections(calib);
    Rig rig;
    Vec3 t0 = Vec3::Zero();
    for (int k = 0; k < 4 && fs::is_directory(cameraDir(k)); ++k) {
      const std::string key{'P', static_cast<char>('0' + k)};  // P0..P3
      const auto it = P.find(key);
      if (it == P.end()) throw InputError(calib + ": no " + key + " for the images in " + cameraDir(k).string());
      const Mat3 K = it->second.leftCols<3>();
      const Vec3 t = K.triangularView<Eigen::Upper>().solve(it->second.col(3));  // x_k = x_rect0 + t_k
      if (k == 0) t0 = t;
      const Image first = firstImage(k);
      RigCamera c;
      c.name = "cam" + std::to_string(k);
      c.source_index = k;
      c.model = CameraModel(first.width(), first.height(), K(0, 0), K(1, 1), K(0, 2), K(1, 2), Distortion::None);
      c.T_b_c = SE3(Mat3::Identity(), t0 - t);  // body = cam0
      rig.cameras.push_back(c);
    }
    if (rig.cameras.empty()) throw InputError(root_ + ": no image_0/ folder");
    return rig;
  }

  std::vector<CameraImage> listImages(int cam, std::vector<std::string>& warnings) const override {
    const std::vector<Timestamp>& t = times();
    const fs::path dir = cameraDir(cam);
    if (!fs::is_directory(dir))
      throw InputError(dir.string() + ": missing (the images of cam" + std::to_string(cam) + ")");
    std::unordered_set<std::string> present;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
      present.insert(it->path().filename().string());
    MissingImageReport missing("cam" + std::to_string(cam), warnings);
    std::vector<CameraImage> images;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const std::string name = imageName(i);
      if (!present.count(name)) {
        missing.add(timesPath() + ": line " + std::to_string(i + 1), (dir / name).string());
        continue;
      }
      if (!images.empty() && t[i] <= images.back().t) {
        throw InputError(timesPath() + ": line " + std::to_string(i + 1) + ": times must increase");
      }
      images.push_back({t[i], (dir / name).string()});
    }
    missing.finish();
    return images;
  }

  std::optional<Trajectory> loadGroundTruth(const Rig& rig, std::vector<std::string>&,
                                            std::string* source) const override {
    // poses.txt beside the images, or the odometry benchmark's dataset/poses/<sequence>.txt.
    const fs::path root = fs::absolute(fs::path(root_)).lexically_normal();
    const fs::path here = root / "poses.txt";
    const fs::path benchmark = root.parent_path().parent_path() / "poses" / (root.filename().string() + ".txt");
    for (const fs::path& p : {here, benchmark}) {
      if (fs::is_regular_file(p)) {
        *source = p.string();
        return readGroundTruthFile(p.string(), rig);
      }
    }
    return std::nullopt;
  }

  Trajectory readGroundTruthFile(const std::string& path, const Rig&) const override {
    return readKittiTrajectory(path, timesPath());
  }

 private:
  fs::path cameraDir(int k) const { return fs::path(root_) / ("image_" + std::to_string(k)); }
  std::string timesPath() const { return (fs::path(root_) / "times.txt").string(); }

  const std::vector<Timestamp>& times() const {
    if (!times_) times_ = readTimesFile(timesPath());
    return *times_;
  }

  // The first image of camera k, which tells its resolution (calib.txt does not).
  Image firstImage(int k) const {
    const std::vector<Timestamp>& t = times();
    for (std::size_t i = 0; i < t.size(); ++i) {
      const fs::path p = cameraDir(k) / imageName(i);
      if (!fs::exists(p)) continue;
      Image img;
      try {
        readGreyImageFile(p.string(), img);
      } catch (const InputError& e) {
        throw InputError(std::string(e.what()) + " (needed for the resolution of cam" + std::to_string(k) + ")");
      }
      return img;
    }
    throw InputError(cameraDir(k).string() + ": none of the " + std::to_string(t.size()) + " images of " + timesPath() +
                     " is there (expected 000000.png, ...)");
  }

  std::string root_;
  mutable std::optional<std::vector<Timestamp>> times_;
};

}  // namespace

std::unique_ptr<DatasetLayout> makeKittiLayout(const std::string& root) { return std::make_unique<KittiLayout>(root); }

}  // namespace mcslam::detail
