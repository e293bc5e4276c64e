#include <gtest/gtest.h>

#include <filesystem>

#include "dataset_test_util.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"

using namespace mcslam;
namespace fs = std::filesystem;

namespace {

// KITTI odometry sequence 00's calibration (fx 718.856, baseline 0.537 m; P2/P3 are the colour cameras).
const char* kCalib =
    "P0: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 0.000000000000e+00 0.000000000000e+00 "
    "7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 0.000000000000e+00 0.000000000000e+00 "
    "1.000000000000e+00 0.000000000000e+00\n"
    "P1: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 -3.861448000000e+02 0.000000000000e+00 "
    "7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 0.000000000000e+00 0.000000000000e+00 "
    "1.000000000000e+00 0.000000000000e+00\n"
    "P2: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 4.538225000000e+01 0.000000000000e+00 "
    "7.188560000000e+02 1.852157000000e+02 -1.130887000000e-01 0.000000000000e+00 0.000000000000e+00 "
    "1.000000000000e+00 3.779761000000e-03\n"
    "P3: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 -3.372877000000e+02 0.000000000000e+00 "
    "7.188560000000e+02 1.852157000000e+02 2.369057000000e+00 0.000000000000e+00 0.000000000000e+00 "
    "1.000000000000e+00 4.915215000000e-03\n"
    "Tr: 4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 -7.210626507497e-03 "
    "8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 9.999738645903e-01 4.859485810390e-04 "
    "-7.206933692422e-03 -2.921968648686e-01\n";

// dataset/sequences/07/{calib.txt,times.txt,image_0,image_1} and dataset/poses/07.txt; image_1/000002.png missing.
std::string writeKitti(const test::TempDir& dir, int frames = 4) {
  const fs::path seq = dir.path() / "dataset" / "sequences" / "07";
  test::writeFile((seq / "calib.txt").string(), kCalib);
  std::string times, poses;
  for (int i = 0; i < frames; ++i) {
    char t[32];
    std::snprintf(t, sizeof(t), "%e\n", 0.1036 * i);
    times += t;
    poses += "1 0 0 0 0 1 0 0 0 0 1 " + std::to_string(0.8 * i) + "\n";
    char name[16];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    test::writePng((seq / "image_0" / name).string(), static_cast<uint8_t>(i), 40, 12);
    if (i != 2) test::writePng((seq / "image_1" / name).string(), static_cast<uint8_t>(50 + i), 40, 12);
  }
  test::writeFile((seq / "times.txt").string(), times);
  test::writeFile((dir.path() / "dataset" / "poses" / "07.txt").string(), poses);
  return seq.string();
}

}  // namespace

TEST(KittiDataset, RigFromRectifiedProjections) {
  test::TempDir dir("kitti");
  const Dataset ds = Dataset::open(writeKitti(dir));
  EXPECT_EQ(ds.format(), "kitti");
  ASSERT_EQ(ds.rig().size(), 2);  // image_2/3 absent: only the grey pair
  const CameraModel& m = ds.rig().model(1);
  EXPECT_DOUBLE_EQ(m.fx(), 718.856);
  EXPECT_DOUBLE_EQ(m.cy(), 185.2157);
  EXPECT_EQ(m.distortion(), Distortion::None);
  EXPECT_EQ(m.width(), 40);  // from the images
  EXPECT_EQ(m.height(), 12);
  // Baseline P1(0,3) / -fx, cam1 to the right (+x) of cam0.
  EXPECT_LT((ds.rig().T_b_c(1).t - Vec3(386.1448 / 718.856, 0, 0)).norm(), 1e-12);
  EXPECT_TRUE(ds.rig().T_b_c(1).R.isIdentity(0));
}

TEST(KittiDataset, ColourCamerasSitWhereTheirProjectionSays) {
  test::TempDir dir("kitti");
  const std::string seq = writeKitti(dir);
  for (int i = 0; i < 4; ++i) {
    char name[16];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    test::writePng(seq + "/image_2/" + name, 1, 40, 12);
    test::writePng(seq + "/image_3/" + name, 1, 40, 12);
  }
  const Rig rig = Dataset::open(seq).rig();
  ASSERT_EQ(rig.size(), 4);
  // t = K^-1 P(:,3) is cam0 -> cam k; the camera sits at -t.
  const double tz = 3.779761e-03, ty = (-1.130887e-01 - 185.2157 * tz) / 718.856,
               tx = (45.38225 - 607.1928 * tz) / 718.856;
  EXPECT_LT((rig.T_b_c(2).t - Vec3(-tx, -ty, -tz)).norm(), 1e-12);
}

TEST(KittiDataset, FramesTimesMissingImageAndBenchmarkPoses) {
  test::TempDir dir("kitti");
  const Dataset ds = Dataset::open(writeKitti(dir));
  ASSERT_EQ(ds.size(), 4u);
  EXPECT_EQ(ds.frames()[0].t, 0);
  EXPECT_EQ(ds.frames()[3].t, 310800000);  // 3.108000e-01 s, exactly
  EXPECT_TRUE(ds.frames()[2].image_paths[1].empty());
  ASSERT_FALSE(ds.warnings().empty());
  EXPECT_NE(ds.warnings()[0].find("times.txt: line 3: image "), std::string::npos) << ds.warnings()[0];
  EXPECT_NE(ds.warnings()[0].find("image_1/000002.png is listed but missing"), std::string::npos) << ds.warnings()[0];
  std::vector<Image> images;
  std::vector<bool> present;
  EXPECT_EQ(ds.loadImages(2, images, present, nullptr), 1);
  EXPECT_EQ(ds.loadImages(3, images, present, nullptr), 2);
  EXPECT_EQ(images[1].data()[0], 53);
  // dataset/poses/07.txt: cam0 poses with the sequence's times.
  ASSERT_TRUE(ds.groundTruth().has_value());
  EXPECT_EQ(ds.groundTruth()->size(), 4u);
  EXPECT_EQ((*ds.groundTruth())[3].t, 310800000);
  EXPECT_NEAR((*ds.groundTruth())[3].T_w_b.t.z(), 2.4, 1e-12);
  EXPECT_NE(ds.groundTruthPath().find("poses/07.txt"), std::string::npos);
}

TEST(KittiDataset, PosesBesideTheImagesOrGivenAsOption) {
  test::TempDir dir("kitti");
  const std::string seq = writeKitti(dir);
  test::writeFile(seq + "/poses.txt", std::string(4, '\n') + "1 0 0 9 0 1 0 0 0 0 1 0\n");  // one pose
  EXPECT_EQ(Dataset::open(seq).groundTruth()->size(), 1u);
  DatasetOptions o;
  o.ground_truth_path = dir.path().string() + "/dataset/poses/07.txt";
  EXPECT_EQ(Dataset::open(seq, o).groundTruth()->size(), 4u);
}

TEST(KittiDataset, MalformedCalibrationNamesFileLineAndMatrix) {
  test::TempDir dir("kitti");
  const std::string seq = writeKitti(dir);
  test::writeFile(seq + "/calib.txt", "P0: 700 0 600 0 0 700 180 0 0 0 1 0\nP1: 700 0 600 -380 0 700 180 0 0 0 1\n");
  try {
    Dataset::open(seq);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(seq + "/calib.txt: line 2: P1 must have 12 numbers"), std::string::npos)
        << e.what();
  }
  test::writeFile(seq + "/calib.txt", "P0: 700 0 600 0 0 700 180 0 0 0 1 0\n");
  try {
    Dataset::open(seq);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no P1 for the images in"), std::string::npos) << e.what();
  }
}
