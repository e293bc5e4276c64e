// The native ASL layout: camchain.yaml, camN/data.csv, camN/data/<ns>.png, optional groundtruth.txt (TUM).
#include <algorithm>
#include <charconv>
#include <filesystem>
#include <sstream>
#include <unordered_set>

#include "dataset_layout.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"

namespace mcslam::detail {

namespace fs = std::filesystem;

namespace {

constexpr int kListedMissing = 5;

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return {};
  const auto b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
}

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream ss(line);
  std::string f;
  while (std::getline(ss, f, ',')) fields.push_back(trim(f));
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

// File names present in a folder, listed once instead of asking the file system for each image.
class AslLayout : public DatasetLayout {
 public:
  explicit AslLayout(std::string root) : root_(std::move(root)) {}
  const char* format() const override { return "asl"; }
  const std::string& root() const override { return root_; }

  Rig loadRig() const override {
    const fs::path calib = fs::path(root_) / "camchain.yaml";
    if (!fs::exists(calib)) {
      throw InputError(
          root_ + ": no camchain.yaml (the ASL layout's Kalibr calibration); give one with the calibration option");
    }
    return loadKalibrRig(calib.string());
  }

  std::vector<CameraImage> listImages(int cam, std::vector<std::string>& warnings) const override {
    return readAslImageList((fs::path(root_) / ("cam" + std::to_string(cam))).string(), warnings);
  }

  std::optional<Trajectory> loadGroundTruth(const Rig&, std::vector<std::string>&, std::string* source) const override {
    const fs::path gt = fs::path(root_) / "groundtruth.txt";
    if (!fs::exists(gt)) return std::nullopt;
    *source = gt.string();
    return readTumTrajectory(gt.string());
  }

 private:
  std::string root_;
};

}  // namespace

std::unordered_set<std::string> fileNames(const fs::path& dir) {
  std::unordered_set<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    names.insert(it->path().filename().string());
  return names;
}

void MissingImageReport::add(const std::string& where, const std::string& path) {
  if (++count_ <= kListedMissing) {
    warnings_.push_back(where + ": image " + path + " is listed but missing; " + camera_ +
                        " is absent from that frame");
  }
}

void MissingImageReport::finish() {
  if (count_ > kListedMissing) {
    warnings_.push_back("... and " + std::to_string(count_ - kListedMissing) + " more listed but missing images of " +
                        camera_);
  }
}

std::vector<CameraImage> readAslImageList(const std::string& camera_dir, std::vector<std::string>& warnings) {
  const fs::path csv = fs::path(camera_dir) / "data.csv";
  const fs::path data = fs::path(camera_dir) / "data";
  const std::string camera = fs::path(camera_dir).filename().string();
  if (!fs::exists(csv)) throw InputError(csv.string() + ": missing (the image list of " + camera + ")");
  std::istringstream in(readTextFile(csv.string()));
  const std::unordered_set<std::string> present = fileNames(data);
  MissingImageReport missing(camera, warnings);

  std::vector<CameraImage> images;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string where = csv.string() + ": line " + std::to_string(line_no);
    const std::string text = trim(line);
    if (text.empty() || text[0] == '#') continue;
    const std::vector<std::string> fields = splitCsv(text);
    if (fields.size() != 2) {
      throw InputError(where + ": expected 'timestamp [ns],filename', got '" + text + "'");
    }
    const std::string& stamp = fields[0];
    Timestamp t = 0;
    const auto [end, ec] = std::from_chars(stamp.data(), stamp.data() + stamp.size(), t);
    if (stamp.empty() || ec != std::errc() || end != stamp.data() + stamp.size() || t < 0) {
      throw InputError(where + ": timestamp is not a whole number of nanoseconds: '" + stamp + "'");
    }
    if (fields[1].empty()) throw InputError(where + ": the file name is empty");
    const fs::path path = data / fields[1];
    // A name the file system refuses (too long, ...) is as missing as one it does not have.
    std::error_code lookup;
    const bool exists =
        fields[1].find('/') == std::string::npos ? present.count(fields[1]) > 0 : fs::exists(path, lookup);
    if (!exists) {
      missing.add(where, path.string());
      continue;
    }
    images.push_back({t, path.string()});
  }
  missing.finish();

  std::stable_sort(images.begin(), images.end(), [](const CameraImage& a, const CameraImage& b) { return a.t < b.t; });
  std::vector<CameraImage> unique;
  for (CameraImage& img : images) {
    if (!unique.empty() && unique.back().t == img.t) {
      warnings.push_back(csv.string() + ": two images at " + std::to_string(img.t) + " ns; keeping " +
                         unique.back().path + ", ignoring " + img.path);
      continue;
    }
    unique.push_back(std::move(img));
  }
  return unique;
}

std::unique_ptr<DatasetLayout> makeAslLayout(const std::string& root) { return std::make_unique<AslLayout>(root); }

}  // namespace mcslam::detail
