#include <gtest/gtest.h>

#include <filesystem>

#include "dataset_test_util.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"

using namespace mcslam;
namespace fs = std::filesystem;

namespace {

// T_BS of tests/data/calib/euroc_cam0_sensor.yaml: cam0 in the EuRoC body (IMU) frame S.
SE3 T_S_cam0() {
  Mat4 M;
  M << 0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,  //
      0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,       //
      -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,   //
      0.0, 0.0, 0.0, 1.0;
  SE3 T = SE3::fromMatrix(M);
  T.normalize();
  return T;
}

SE3 T_w_S(int i) {
  return SE3(Eigen::AngleAxisd(0.2 * i, Vec3(0.3, -0.5, 1).normalized()).toRotationMatrix(), Vec3(4.5 + i, -1.8, 0.8));
}

constexpr Timestamp kT0 = 1403636579763555584LL;
constexpr Timestamp kPeriod = 50000000;

// The EuRoC MAV layout: <root>/mav0/cam{0,1}/{sensor.yaml,data.csv,data/}, state_groundtruth_estimate0/data.csv.
std::string writeEuroc(const test::TempDir& dir) {
  const fs::path mav0 = dir.path() / "MH_01" / "mav0";
  for (int c = 0; c < 2; ++c) {
    const fs::path cam = mav0 / ("cam" + std::to_string(c));
    fs::create_directories(cam / "data");
    fs::copy_file(test::dataPath("calib/euroc_cam" + std::to_string(c) + "_sensor.yaml"), cam / "sensor.yaml");
    std::string csv = "#timestamp [ns],filename\r\n";  // EuRoC's files have CRLF line ends
    for (int i = 0; i < 3; ++i) {
      const std::string name = std::to_string(kT0 + i * kPeriod) + ".png";
      test::writePng((cam / "data" / name).string(), static_cast<uint8_t>(100 + i), 752, 480);
      csv += std::to_string(kT0 + i * kPeriod) + "," + name + "\r\n";
    }
    test::writeFile((cam / "data.csv").string(), csv);
  }
  std::string gt =
      "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], v_RS_R_x [m "
      "s^-1], "
      "v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], "
      "b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";
  for (int i = 0; i < 3; ++i) {
    const SE3 T = T_w_S(i);
    const Eigen::Quaterniond q = T.quaternion();
    char row[512];
    std::snprintf(row, sizeof(row), "%lld,%.12f,%.12f,%.12f,%.15f,%.15f,%.15f,%.15f,0.1,0,0,0,0,0,0,0,0\n",
                  static_cast<long long>(kT0 + i * kPeriod + 5000), T.t.x(), T.t.y(), T.t.z(), q.w(), q.x(), q.y(),
                  q.z());
    gt += row;
  }
  test::writeFile((mav0 / "state_groundtruth_estimate0" / "data.csv").string(), gt);
  return (dir.path() / "MH_01").string();
}

}  // namespace

TEST(EurocDataset, GroundTruthIsConvertedFromTheImuToCam0) {
  test::TempDir dir("euroc");
  const Dataset ds = Dataset::open(writeEuroc(dir));
  EXPECT_EQ(ds.format(), "euroc");
  ASSERT_EQ(ds.rig().size(), 2);
  EXPECT_NEAR((ds.rig().T_b_c(1).t - ds.rig().T_b_c(0).t).norm(), 0.110, 0.002);  // the VI-sensor's stereo baseline
  ASSERT_TRUE(ds.groundTruth().has_value());
  ASSERT_EQ(ds.groundTruth()->size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const StampedPose& p = (*ds.groundTruth())[i];
    const SE3 expected = T_w_S(i) * T_S_cam0();  // the pose of cam0 (= our body) in the world
    EXPECT_EQ(p.t, kT0 + i * kPeriod + 5000);
    EXPECT_LT((p.T_w_b.t - expected.t).norm(), 1e-9) << i;
    EXPECT_LT((p.T_w_b.R - expected.R).norm(), 1e-9) << i;
  }
}

TEST(EurocDataset, ReadsFramesAndImagesFromTheParentOrMav0Itself) {
  test::TempDir dir("euroc");
  const std::string root = writeEuroc(dir);
  for (const std::string& path : {root, root + "/mav0"}) {
    const Dataset ds = Dataset::open(path);
    ASSERT_EQ(ds.size(), 3u) << path;
    EXPECT_EQ(ds.frames()[2].t, kT0 + 2 * kPeriod);
    std::vector<Image> images;
    std::vector<bool> present;
    std::string error;
    ASSERT_EQ(ds.loadImages(1, images, present, &error), 2) << error;
    EXPECT_EQ(images[1].width(), 752);
    EXPECT_EQ(images[1].data()[0], 101);
  }
}

TEST(EurocDataset, MalformedGroundTruthNamesFileAndLine) {
  test::TempDir dir("euroc");
  const std::string root = writeEuroc(dir);
  const std::string gt = root + "/mav0/state_groundtruth_estimate0/data.csv";
  test::writeFile(gt, "#timestamp, ...\n1403636579763555584,1,2,3,1,0,0,0\n1403636579813555584,1,2,three,1,0,0,0\n");
  try {  // what needs the ground truth gets the file's error; the images stay usable without it
    Dataset::open(root).requireGroundTruth();
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(gt + ": line 3: p_RS_R_z is not a number: 'three'"), std::string::npos)
        << e.what();
  }
  test::writeFile(gt, "1403636579763555584,1,2,3\n");
  EXPECT_THROW(Dataset::open(root).requireGroundTruth(), InputError);
}
