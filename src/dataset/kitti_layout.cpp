// The KITTI odometry layout: image_0/ .. image_3/ (<index>.png, six digits), calib.txt with the rectified
// 3x4 projection matrices P0..P3, times.txt (seconds), optional cam0 poses (KITTI format).
// P_k = K_k [I | t_k]: every rectified camera has cam0's orientation and sits at -t_k in cam0's frame (for the
// stereo pair t_1 = (P1(0,3) / fx, 0, 0), i.e. the baseline is P1(0,3) / -fx).
#include <cstdio>
#include <filesystem>
#include <unordered_set>

#include "dataset_layout.hpp"
#include "kitti_calib.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/image_file.hpp"

namespace mcslam::detail {

namespace fs = std::filesystem;

namespace {

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
    const KittiCalibFile calib((fs::path(root_) / "calib.txt").string());
    Rig rig;
    for (int k = 0; k < 4 && fs::is_directory(cameraDir(k)); ++k) {
      const std::string key{'P', static_cast<char>('0' + k)};  // P0..P3
      if (!calib.has(key)) {
        throw InputError(calib.path() + ": no " + key + " for the images in " + cameraDir(k).string());
      }
      const Image first = firstImage(k);
      rig.cameras.push_back(rectifiedCamera(k, calib.rectifiedProjection(key), calib.rectifiedProjection("P0"),
                                            first.width(),
                                            first.height()));  // body = cam0
    }
    if (rig.cameras.empty()) throw InputError(root_ + ": no image_0/ folder");
    return rig;
  }

  std::vector<CameraImage> listImages(int cam, std::vector<std::string>& warnings) const override {
    const fs::path dir = cameraDir(cam);
    if (!fs::is_directory(dir))
      throw InputError(dir.string() + ": missing (the images of cam" + std::to_string(cam) + ")");
    return indexedImages(dir, cam, times(), timesPath(), imageName, warnings);
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

std::vector<CameraImage> indexedImages(const fs::path& dir, int cam, const std::vector<Timestamp>& times,
                                       const std::string& times_path, std::string (*name)(std::size_t),
                                       std::vector<std::string>& warnings) {
  const std::unordered_set<std::string> present = fileNames(dir);
  MissingImageReport missing("cam" + std::to_string(cam), warnings);
  std::vector<CameraImage> images;
  for (std::size_t i = 0; i < times.size(); ++i) {
    const std::string where = times_path + ": line " + std::to_string(i + 1);
    const std::string file = name(i);
    if (!present.count(file)) {
      missing.add(where, (dir / file).string());
      continue;
    }
    if (!images.empty() && times[i] <= images.back().t) throw InputError(where + ": times must increase");
    images.push_back({times[i], (dir / file).string()});
  }
  missing.finish();
  return images;
}

std::unique_ptr<DatasetLayout> makeKittiLayout(const std::string& root) { return std::make_unique<KittiLayout>(root); }

}  // namespace mcslam::detail
