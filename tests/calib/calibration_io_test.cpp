#include <gtest/gtest.h>

#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "test_support.hpp"

using namespace mcslam;

namespace {

const char* kTwoCams = R"(cam0:
  camera_model: pinhole
  intrinsics: [400, 401, 320, 240]
  distortion_model: radtan
  distortion_coeffs: [-0.1, 0.01, 0.001, -0.001]
  resolution: [640, 480]
cam1:
  T_cn_cnm1:
    - [1, 0, 0, -0.2]
    - [0, 1, 0, 0]
    - [0, 0, 1, 0]
    - [0, 0, 0, 1]
  camera_model: pinhole
  intrinsics: [400, 401, 320, 240]
  distortion_model: equidistant
  distortion_coeffs: [0.01, 0.0, 0.0, 0.0]
  resolution: [800, 600]
)";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Parses and expects an InputError whose message contains every given fragment.
void expectRejected(const std::string& text, std::initializer_list<std::string> fragments) {
  try {
    parseKalibrRig(text, "rig.yaml");
    FAIL() << "accepted bad calibration";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const auto& f : fragments) EXPECT_NE(msg.find(f), std::string::npos) << "'" << f << "' not in: " << msg;
  }
}

}  // namespace

TEST(KalibrRig, ReadsThePapersFiveCameraRigWithOpenCvHeader) {
  const Rig rig = loadKalibrRig(test::dataPath("calib/isec_5cam_camchain.yaml"));
  ASSERT_EQ(rig.size(), 5);
  EXPECT_TRUE(rig.T_b_c(0).matrix().isIdentity(1e-12));
  for (int i = 1; i < 5; ++i) {
    const double baseline = (rig.T_b_c(i).t - rig.T_b_c(i - 1).t).norm();
    EXPECT_NEAR(baseline, 0.165, 0.005) << "cam" << i;
    EXPECT_EQ(rig.model(i).width(), 720);
    EXPECT_EQ(rig.model(i).distortion(), Distortion::RadTan);
  }
  EXPECT_NEAR(rig.model(2).fx(), 889.290678506305, 1e-9);
  EXPECT_FALSE(rig.T_b_imu.has_value());
}

TEST(KalibrRig, ChainsThroughTheImuWhenThereIsNoCameraChain) {
  // EuRoC chain (T_imu_cam) and the EuRoC sensor.yaml files describe the same rig.
  const Rig chain = loadKalibrRig(test::dataPath("calib/euroc_kalibr_imucam_chain.yaml"));
  const Rig sensors = loadEurocSensorRig(
      {test::dataPath("calib/euroc_cam0_sensor.yaml"), test::dataPath("calib/euroc_cam1_sensor.yaml")});
  ASSERT_EQ(chain.size(), 2);
  ASSERT_EQ(sensors.size(), 2);
  EXPECT_LT((chain.T_b_c(1).matrix() - sensors.T_b_c(1).matrix()).norm(), 1e-6);
  EXPECT_NEAR(chain.T_b_c(1).t.norm(), 0.110, 0.002);  // EuRoC stereo baseline ~11 cm
  ASSERT_TRUE(chain.T_b_imu && sensors.T_b_imu);
  EXPECT_LT((chain.T_b_imu->matrix() - sensors.T_b_imu->matrix()).norm(), 1e-9);
  EXPECT_NEAR(sensors.model(1).coeffs()[0], -0.28368365, 1e-12);

  const Rig tumvi = loadKalibrRig(test::dataPath("calib/tumvi_kalibr_imucam_chain.yaml"));
  ASSERT_EQ(tumvi.size(), 2);
  EXPECT_EQ(tumvi.model(0).distortion(), Distortion::Equidistant);
  EXPECT_EQ(tumvi.model(1).width(), 512);
  EXPECT_NEAR(tumvi.T_b_c(1).t.norm(), 0.101, 0.003);
}

TEST(KalibrRig, CamerasMayDifferAndBodyFrameCanBeGiven) {
  RigLoadOptions opt;
  opt.T_body_cam0 = SE3(Mat3::Identity(), Vec3(0.1, 0, 0));
  const Rig rig = parseKalibrRig(kTwoCams, "two.yaml", opt);
  ASSERT_EQ(rig.size(), 2);
  EXPECT_EQ(rig.model(1).width(), 800);
  EXPECT_EQ(rig.model(1).distortion(), Distortion::Equidistant);
  EXPECT_LT((rig.T_b_c(0).t - Vec3(0.1, 0, 0)).norm(), 1e-12);
  EXPECT_LT((rig.T_b_c(1).t - Vec3(0.3, 0, 0)).norm(), 1e-12);
}

TEST(KalibrRig, WriteThenReadGivesTheSameRig) {
  const Rig rig = loadKalibrRig(test::dataPath("calib/tumvi_kalibr_imucam_chain.yaml"));
  const Rig back = parseKalibrRig(formatKalibrRig(rig), "written.yaml");
  ASSERT_EQ(back.size(), rig.size());
  for (int i = 0; i < rig.size(); ++i) {
    EXPECT_LT((back.T_b_c(i).matrix() - rig.T_b_c(i).matrix()).norm(), 1e-12);
    EXPECT_EQ(back.model(i).coeffs(), rig.model(i).coeffs());
    EXPECT_EQ(back.model(i).distortion(), rig.model(i).distortion());
  }
  ASSERT_TRUE(back.T_b_imu);
  EXPECT_LT((back.T_b_imu->matrix() - rig.T_b_imu->matrix()).norm(), 1e-12);
}

TEST(KalibrRig, BadCalibrationNamesFileCameraAndField) {
  expectRejected(replaced(kTwoCams, "  intrinsics: [400, 401, 320, 240]\n  distortion_model: equidistant",
                          "  distortion_model: equidistant"),
                 {"rig.yaml", "cam1", "intrinsics", "missing"});
  expectRejected(replaced(kTwoCams, "[400, 401, 320, 240]", "[400, 401, 320]"),
                 {"rig.yaml", "cam0", "intrinsics", "4 numbers", "got 3"});
  expectRejected(replaced(kTwoCams, "camera_model: pinhole", "camera_model: omni"), {"cam0", "camera_model", "omni"});
  expectRejected(replaced(kTwoCams, "distortion_model: radtan", "distortion_model: fov"),
                 {"cam0", "distortion_model", "fov"});
  expectRejected(replaced(kTwoCams, "[-0.1, 0.01, 0.001, -0.001]", "[-0.1, abc, 0.001, -0.001]"),
                 {"cam0", "distortion_coeffs", "abc"});
  expectRejected(replaced(kTwoCams, "- [1, 0, 0, -0.2]", "- [1, 0.5, 0, -0.2]"), {"cam1", "T_cn_cnm1", "rigid"});
  expectRejected(replaced(kTwoCams, "- [0, 0, 0, 1]", "- [0, 0, 1, 1]"), {"cam1", "T_cn_cnm1", "last row"});
  expectRejected(replaced(kTwoCams, "[640, 480]", "[640, 480.5]"), {"cam0", "resolution"});
  expectRejected(replaced(kTwoCams, "cam1:", "cam2:"), {"rig.yaml", "cam1", "missing"});
  expectRejected("something: 1\n", {"rig.yaml", "no cameras"});
  expectRejected("cam0: [unclosed\n", {"rig.yaml", "YAML"});
  // Coefficients without a model were dropped: the lens taken for a distortion-free one.
  expectRejected(replaced(kTwoCams, "  distortion_model: radtan\n", ""),
                 {"rig.yaml", "cam0", "distortion_coeffs", "without distortion_model"});
  // A key given twice: the parser kept one silently.
  expectRejected(replaced(kTwoCams, "camera_model: pinhole", "camera_model: pinhole\n  camera_model: omni"),
                 {"rig.yaml", "cam0.camera_model", "appears twice", "line"});
  expectRejected(
      replaced(kTwoCams, "    - [1, 0, 0, -0.2]\n    - [0, 1, 0, 0]\n    - [0, 0, 1, 0]\n    - [0, 0, 0, 1]\n", ""),
      {"cam1", "T_cn_cnm1"});
  try {
    loadKalibrRig("/nonexistent/rig.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/rig.yaml"), std::string::npos);
  }
  // A device that never ends is read only up to what a calibration file could hold, then refused.
  try {
    loadKalibrRig("/dev/zero");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/zero: larger than 16 MB"), std::string::npos) << e.what();
  }
}

// A rig has at most 64 cameras (kMaxRigCameras): a file with more, or with a camera index no int holds, is refused
// by name; cam01 beside cam1 would be two keys for one camera.
TEST(KalibrRig, CameraKeysAreBoundedAndWrittenOnce) {
  Rig rig = parseKalibrRig(kTwoCams, "two.yaml");
  while (rig.size() < kMaxRigCameras) rig.cameras.push_back(rig.cameras[1]);
  const std::string sixty_four = formatKalibrRig(rig);
  EXPECT_EQ(parseKalibrRig(sixty_four, "64.yaml").size(), 64);
  rig.cameras.push_back(rig.cameras[1]);
  expectRejected(formatKalibrRig(rig), {"rig.yaml: cam64: a rig has at most 64 cameras"});
  expectRejected("cam99999999999: {}\n", {"rig.yaml: cam99999999999: a rig has at most 64 cameras"});
  expectRejected(replaced(kTwoCams, "cam1:", "cam01:"), {"rig.yaml: cam01", "without leading zeros"});
}

TEST(Rig, SubsetKeepsTheBodyFrame) {
  const Rig rig = loadKalibrRig(test::dataPath("calib/isec_5cam_camchain.yaml"));
  const Rig sub = rig.subset(parseCameraList("4,2"));
  ASSERT_EQ(sub.size(), 2);
  EXPECT_EQ(sub.cameras[0].source_index, 4);
  EXPECT_LT((sub.T_b_c(0).matrix() - rig.T_b_c(4).matrix()).norm(), 1e-15);
  EXPECT_THROW(rig.subset({0, 5}), InputError);
  EXPECT_THROW(rig.subset({1, 1}), InputError);
  EXPECT_THROW(parseCameraList("0,x"), InputError);
  EXPECT_THROW(parseCameraList(""), InputError);
}
