// The KITTI raw layout, as its "synced+rectified" download comes: a drive folder with image_00/ .. image_03/
// (data/<index, ten digits>.png, timestamps.txt with one date and time a line, line i for image i) and
// calib_cam_to_cam.txt in the drive folder or, as the download lays it out, in the date folder above it.
// Cameras 00/01 are grey, 02/03 colour (read as grey). Only the rectified entries are read: P_rect_0N = K [I | t]
// and S_rect_0N (the rectified image size); the body frame is rectified camera 0. R_rect_00 and
// calib_velo_to_cam.txt relate that frame to the unrectified camera 0 and to the Velodyne, which the images do not
// need, so they are not read. No ground truth (the drive's GPS/IMU, oxts/, is not read).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <sstream>

#include "dataset_layout.hpp"
#include "kitti_calib.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"

namespace mcslam::detail {

namespace fs = std::filesystem;

namespace {

constexpr const char* kCalibName = "calib_cam_to_cam.txt";

// "2011-09-26 13:02:25.967790592" -> nanoseconds since 1970-01-01 00:00 of the same clock (KITTI gives no time
// zone; only differences matter). False when the text has another form.
bool parseDateTime(const std::string& text, Timestamp& t) {
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, s = 0, used = 0;
  if (std::sscanf(text.c_str(), "%4d-%2d-%2d %2d:%2d:%2d%n", &y, &mo, &d, &h, &mi, &s, &used) != 6) return false;
  const std::chrono::year_month_day date{std::chrono::year(y), std::chrono::month(mo), std::chrono::day(d)};
  if (!date.ok() || h > 23 || mi > 59 || s > 60 || h < 0 || mi < 0 || s < 0) return false;
  std::string fraction = text.substr(used);
  if (!fraction.empty()) {
    if (fraction[0] != '.' || fraction.size() < 2 || fraction.size() > 10) return false;
    fraction.erase(0, 1);
    if (fraction.find_first_not_of("0123456789") != std::string::npos) return false;
  }
  const Timestamp days = std::chrono::sys_days(date).time_since_epoch().count();
  t = ((days * 24 + h) * 60 + mi) * 60 + s;
  t = t * 1000000000 + (fraction.empty() ? 0 : std::stoll((fraction + "00000000").substr(0, 9)));
  return true;
}

std::vector<Timestamp> readDateTimes(const std::string& path) {
  std::vector<std::string> lines;
  std::istringstream in(readTextFile(path));
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  while (!lines.empty() && lines.back().find_first_not_of(" \t") == std::string::npos) lines.pop_back();
  std::vector<Timestamp> times(lines.size());
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (!parseDateTime(lines[i], times[i])) {
      throw InputError(path + ": line " + std::to_string(i + 1) + " (image " + std::to_string(i) +
                       "): expected 'YYYY-MM-DD hh:mm:ss.fraction', got '" + lines[i] + "'");
    }
  }
  return times;
}

// "P_rect_" and 2 -> "P_rect_02".
std::string entryName(const char* prefix, int camera) {
  std::string name(prefix);
  name += '0';
  name += static_cast<char>('0' + camera);
  return name;
}

std::string imageName(std::size_t index) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%010zu.png", index);
  return buf;
}

class KittiRawLayout : public DatasetLayout {
 public:
  KittiRawLayout(std::string root, std::string calib) : root_(std::move(root)), calib_(std::move(calib)) {}
  const char* format() const override { return "kitti_raw"; }
  const std::string& root() const override { return root_; }

  Rig loadRig() const override {
    const KittiCalibFile calib(calib_);
    Rig rig;
    for (int k = 0; k < 4 && fs::is_directory(cameraDir(k)); ++k) {
      const std::string projection = entryName("P_rect_", k), size = entryName("S_rect_", k);
      for (const std::string& key : {projection, size}) {
        if (!calib.has(key)) throw InputError(calib_ + ": no " + key + " for the images in " + cameraDir(k).string());
      }
      const auto [width, height] = rectifiedSize(calib, size);
      rig.cameras.push_back(rectifiedCamera(k, calib.rectifiedProjection(projection),
                                            calib.rectifiedProjection("P_rect_00"), width, height));
    }
    if (rig.cameras.empty()) throw InputError(root_ + ": no image_00/ folder");
    return rig;
  }

  std::vector<CameraImage> listImages(int cam, std::vector<std::string>& warnings) const override {
    const fs::path dir = cameraDir(cam) / "data";
    const std::string times_path = (cameraDir(cam) / "timestamps.txt").string();
    if (!fs::exists(times_path))
      throw InputError(times_path + ": missing (the times of cam" + std::to_string(cam) + ")");
    return indexedImages(dir, cam, readDateTimes(times_path), times_path, imageName, warnings);
  }

  std::optional<Trajectory> loadGroundTruth(const Rig&, std::vector<std::string>&, std::string*) const override {
    return std::nullopt;
  }

  // The four cameras are triggered together, but each stamps its own images: the colour pair's stamps lie up to
  // about 10 ms before the grey pair's. A third of the frame period pairs them and never two frames.
  Timestamp syncTolerance(const std::vector<std::vector<CameraImage>>& images) const override {
    return automaticSyncTolerance(images, std::numeric_limits<Timestamp>::max());
  }

 private:
  fs::path cameraDir(int k) const { return fs::path(root_) / entryName("image_", k); }

  static std::pair<int, int> rectifiedSize(const KittiCalibFile& calib, const std::string& key) {
    const std::vector<double> s = calib.numbers(key, 2, "the rectified image's width and height");
    for (double v : s) {
      if (!(v >= 1 && v <= 100000 && v == std::floor(v))) {
        std::ostringstream got;
        got << s[0] << " " << s[1];
        throw InputError(calib.where(key) + " must be two whole numbers of pixels (width height), got " + got.str());
      }
    }
    return {static_cast<int>(s[0]), static_cast<int>(s[1])};
  }

  std::string root_;
  std::string calib_;
};

}  // namespace

std::optional<std::string> findKittiRawCalibration(const std::string& dir) {
  const fs::path d = fs::absolute(fs::path(dir)).lexically_normal();
  const fs::path folder = d.has_filename() ? d : d.parent_path();  // "drive/" ends in an empty file name
  for (const fs::path& p : {folder / kCalibName, folder.parent_path() / kCalibName}) {
    if (fs::is_regular_file(p)) return p.string();
  }
  return std::nullopt;
}

std::unique_ptr<DatasetLayout> makeKittiRawLayout(const std::string& root, const std::string& calibration) {
  return std::make_unique<KittiRawLayout>(root, calibration);
}

}  // namespace mcslam::detail
