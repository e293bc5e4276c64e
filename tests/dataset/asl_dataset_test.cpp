#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "dataset_test_util.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"

using namespace mcslam;
namespace fs = std::filesystem;

namespace {

constexpr Timestamp kT0 = 1700000000000000000LL;
constexpr Timestamp kPeriod = 50000000;  // 20 Hz

Timestamp stamp(int i) { return kT0 + i * kPeriod; }

// Three cameras, five frames; cam1 has no image at frame 2; pixel value = 10 * camera + frame.
std::string writeDataset(const test::TempDir& dir) {
  const std::string root = dir.file("asl");
  AslDatasetWriter w(root, test::smallRig(3));
  for (int i = 0; i < 5; ++i) {
    for (int c = 0; c < 3; ++c) {
      if (c == 1 && i == 2) continue;
      w.writeImage(c, stamp(i) + c * 1000,
                   test::FlatImage(static_cast<uint8_t>(10 * c + i)).image.view());  // 1 us jitter
    }
  }
  Trajectory gt;
  for (int i = 0; i < 5; ++i) gt.push_back({stamp(i), SE3(Mat3::Identity(), Vec3(i, 0, 0))});
  w.writeGroundTruth(gt);
  w.close();
  return root;
}

bool contains(const std::vector<std::string>& lines, const std::string& part) {
  for (const auto& l : lines) {
    if (l.find(part) != std::string::npos) return true;
  }
  return false;
}

}  // namespace

TEST(AslDataset, ReadsFramesImagesAndGroundTruth) {
  test::TempDir dir("asl");
  const Dataset ds = Dataset::open(writeDataset(dir));
  EXPECT_EQ(ds.format(), "asl");
  ASSERT_EQ(ds.rig().size(), 3);
  ASSERT_EQ(ds.size(), 5u);
  EXPECT_EQ(ds.frames()[3].t, stamp(3));
  EXPECT_EQ(ds.frames()[3].camera_stamps[2], stamp(3) + 2000);
  EXPECT_EQ(ds.syncToleranceNs(), 5000000);  // min(period / 3, 5 ms)
  ASSERT_TRUE(ds.groundTruth().has_value());
  EXPECT_EQ(ds.groundTruth()->size(), 5u);
  EXPECT_EQ((*ds.groundTruth())[4].T_w_b.t, Vec3(4, 0, 0));
  EXPECT_NE(ds.groundTruthPath().find("groundtruth.txt"), std::string::npos);

  std::vector<Image> images;
  std::vector<bool> present;
  std::string error;
  ASSERT_EQ(ds.loadImages(3, images, present, &error), 3) << error;
  EXPECT_TRUE(error.empty());
  for (int c = 0; c < 3; ++c) {
    ASSERT_TRUE(present[c]);
    EXPECT_EQ(images[c].width(), test::kWidth);
    EXPECT_EQ(images[c].data()[0], 10 * c + 3) << "cam" << c;
  }
}

TEST(AslDataset, ACameraMissingOneFrameIsAbsentThereNotShifted) {
  test::TempDir dir("asl");
  const Dataset ds = Dataset::open(writeDataset(dir));
  ASSERT_EQ(ds.size(), 5u);
  EXPECT_TRUE(ds.frames()[2].image_paths[1].empty());
  std::vector<Image> images;
  std::vector<bool> present;
  EXPECT_EQ(ds.loadImages(2, images, present, nullptr), 2);
  EXPECT_FALSE(present[1]);
  EXPECT_EQ(images[2].data()[0], 22);
  // The next frame pairs cam1's own next image with the others'.
  ASSERT_EQ(ds.loadImages(3, images, present, nullptr), 3);
  EXPECT_EQ(images[1].data()[0], 13);
  EXPECT_TRUE(contains(ds.warnings(), "1 of 5 rig frames lack at least one camera"));
}

TEST(AslDataset, AListedButMissingFileIsAWarningAndTheFrameStays) {
  test::TempDir dir("asl");
  const std::string root = writeDataset(dir);
  const std::string gone = root + "/cam2/data/" + std::to_string(stamp(1) + 2000) + ".png";
  ASSERT_TRUE(fs::remove(gone));
  const Dataset ds = Dataset::open(root);
  ASSERT_EQ(ds.size(), 5u);
  EXPECT_TRUE(ds.frames()[1].image_paths[2].empty());
  EXPECT_FALSE(ds.frames()[1].image_paths[0].empty());
  EXPECT_TRUE(contains(ds.warnings(), root + "/cam2/data.csv: line 3: image " + gone + " is listed but missing"));
}

// A listed name the file system refuses to look up (a folder name beyond NAME_MAX) is missing like any other.
TEST(AslDataset, AListedNameTheFileSystemRefusesIsMissingNotAnException) {
  test::TempDir dir("asl");
  const std::string root = writeDataset(dir);
  std::ofstream(root + "/cam2/data.csv", std::ios::app) << stamp(9) << ",sub" << std::string(300, 'x') << "/a.png\n";
  const Dataset ds = Dataset::open(root);
  EXPECT_EQ(ds.size(), 5u);
  EXPECT_TRUE(contains(ds.warnings(), root + "/cam2/data.csv: line 7: image "));
}

TEST(AslDataset, AnUnreadableImageIsReportedAndItsCameraMarkedAbsent) {
  test::TempDir dir("asl");
  const std::string root = writeDataset(dir);
  const std::string broken = root + "/cam0/data/" + std::to_string(stamp(4)) + ".png";
  test::writeFile(broken, "this is not a png");
  const Dataset ds = Dataset::open(root);
  std::vector<Image> images;
  std::vector<bool> present;
  std::string error;
  EXPECT_EQ(ds.loadImages(4, images, present, &error), 2);
  EXPECT_FALSE(present[0]);
  EXPECT_TRUE(present[1] && present[2]);
  EXPECT_NE(error.find(broken + ": cannot read image"), std::string::npos) << error;
  // A wrong size is reported too: a larger image is not even decoded.
  test::writePng(broken, 7, test::kWidth * 2, test::kHeight);
  EXPECT_EQ(ds.loadImages(4, images, present, &error), 2);
  EXPECT_NE(error.find("image is 32x12, larger than the 16x12 this camera has"), std::string::npos) << error;
  test::writePng(broken, 7, test::kWidth / 2, test::kHeight);
  EXPECT_EQ(ds.loadImages(4, images, present, &error), 2);
  EXPECT_NE(error.find("is 8x12 but the calibration of cam0 says 16x12"), std::string::npos) << error;
  // Frames out of range are an error message, not a crash.
  EXPECT_EQ(ds.loadImages(99, images, present, &error), 0);
  EXPECT_NE(error.find("frame 99 does not exist"), std::string::npos) << error;
}

TEST(AslDataset, MalformedCsvNamesFileAndLine) {
  test::TempDir dir("asl");
  const std::string root = writeDataset(dir);
  const std::string csv = root + "/cam1/data.csv";
  for (const auto& [row, fragment] : std::vector<std::pair<std::string, std::string>>{
           {"1700000000.5,x.png", "timestamp is not a whole number of nanoseconds: '1700000000.5'"},
           {"1700000000000000000", "expected 'timestamp [ns],filename'"},
           {"1700000000000000000,a.png,extra", "expected 'timestamp [ns],filename'"},
           {"1700000000000000000,", "the file name is empty"}}) {
    test::writeFile(csv, "#timestamp [ns],filename\n" + std::to_string(stamp(0) + 1000) + "," +
                             std::to_string(stamp(0) + 1000) + ".png\n" + row + "\n");
    try {
      Dataset::open(root);
      FAIL() << "accepted " << row;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(csv + ": line 3: " + fragment), std::string::npos) << e.what();
    }
  }
}

TEST(AslDataset, CameraSubsetKeepsTheFullRigsBodyFrame) {
  test::TempDir dir("asl");
  DatasetOptions o;
  o.cameras = {2, 1};
  const Dataset ds = Dataset::open(writeDataset(dir), o);
  ASSERT_EQ(ds.rig().size(), 2);
  EXPECT_EQ(ds.rig().cameras[0].source_index, 2);
  EXPECT_LT((ds.rig().T_b_c(0).t - Vec3(0.2, 0, 0)).norm(), 1e-12);
  std::vector<Image> images;
  std::vector<bool> present;
  ASSERT_EQ(ds.loadImages(0, images, present, nullptr), 2);
  EXPECT_EQ(images[0].data()[0], 20);  // cam2 first
  EXPECT_EQ(images[1].data()[0], 10);
  o.cameras = {5};
  EXPECT_THROW(Dataset::open(dir.file("asl"), o), InputError);
}

TEST(AslDataset, CalibrationOverrideAndToleranceOption) {
  test::TempDir dir("asl");
  const std::string root = writeDataset(dir);
  Rig other = test::smallRig(3);
  other.cameras[1].T_b_c.t = Vec3(0, 0.5, 0);
  writeKalibrRig(other, dir.file("other.yaml"));
  DatasetOptions o;
  o.calibration_override = dir.file("other.yaml");
  o.sync_tolerance_ns = 1500;  // 1.5 us: cam2's 2 us offset no longer fits, cam1's 1 us does
  const Dataset ds = Dataset::open(root, o);
  EXPECT_LT((ds.rig().T_b_c(1).t - Vec3(0, 0.5, 0)).norm(), 1e-9);
  EXPECT_EQ(ds.syncToleranceNs(), 1500);
  EXPECT_EQ(ds.size(), 10u);
  EXPECT_TRUE(ds.frames()[0].image_paths[2].empty());
  EXPECT_FALSE(ds.frames()[0].image_paths[1].empty());
}

TEST(AslDataset, GroundTruthOverrideAndNoGroundTruth) {
  test::TempDir dir("asl");
  const std::string root = writeDataset(dir);
  fs::remove(root + "/groundtruth.txt");
  EXPECT_FALSE(Dataset::open(root).groundTruth().has_value());
  writeTumTrajectory(dir.file("gt.txt"), {{stamp(0), SE3()}});
  DatasetOptions o;
  o.ground_truth_path = dir.file("gt.txt");
  const Dataset ds = Dataset::open(root, o);
  ASSERT_TRUE(ds.groundTruth().has_value());
  EXPECT_EQ(ds.groundTruth()->size(), 1u);
  EXPECT_EQ(ds.groundTruthPath(), dir.file("gt.txt"));
}

// A dataset's own ground truth that cannot be read does not stop what needs only the images: it is left out with a
// warning, and what needs it gets the file's error.
TEST(AslDataset, AnUnreadableGroundTruthIsLeftOutWithAWarningAndItsReasonKept) {
  test::TempDir dir("asl");
  const std::string root = writeDataset(dir);
  test::writeFile(root + "/groundtruth.txt", "garbage line here\n");
  const Dataset ds = Dataset::open(root);
  EXPECT_GT(ds.size(), 0u);
  EXPECT_FALSE(ds.groundTruth().has_value());
  ASSERT_FALSE(ds.warnings().empty());
  EXPECT_NE(ds.warnings().back().find("groundtruth.txt"), std::string::npos) << ds.warnings().back();
  try {
    ds.requireGroundTruth();
    FAIL() << "no ground truth, no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("groundtruth.txt: line 1"), std::string::npos) << e.what();
  }
  fs::remove(root + "/groundtruth.txt");
  try {
    Dataset::open(root).requireGroundTruth();
    FAIL() << "no ground truth, no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("has no ground truth"), std::string::npos) << e.what();
  }
}

TEST(AslDataset, NotADatasetIsAClearError) {
  test::TempDir dir("asl");
  for (const std::string& path : {dir.file("nothing"), dir.path().string()}) {
    try {
      Dataset::open(path);
      FAIL() << path;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + ": "), std::string::npos) << e.what();
    }
  }
  const std::string root = writeDataset(dir);
  fs::remove_all(root + "/cam2");
  try {
    Dataset::open(root);
    FAIL() << "cam2 missing";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(root + "/cam2/data.csv: missing"), std::string::npos) << e.what();
  }
}
