#include <gtest/gtest.h>

#include "dataset_test_util.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"

using namespace mcslam;

TEST(LoadRigFromPath, KalibrYamlEurocSensorYamlAndDatasetFolder) {
  EXPECT_EQ(loadRigFromPath(test::dataPath("calib/isec_5cam_camchain.yaml")).size(), 5);
  const Rig euroc = loadRigFromPath(test::dataPath("calib/euroc_cam1_sensor.yaml"));
  ASSERT_EQ(euroc.size(), 1);
  EXPECT_EQ(euroc.model(0).width(), 752);
  EXPECT_TRUE(euroc.T_b_imu.has_value());

  test::TempDir dir("rig");
  {
    AslDatasetWriter w(dir.file("asl"), test::smallRig(3));
    w.close();
  }
  const Rig from_folder = loadRigFromPath(dir.file("asl"));
  ASSERT_EQ(from_folder.size(), 3);
  EXPECT_LT((from_folder.T_b_c(2).t - Vec3(0.2, 0, 0)).norm(), 1e-12);
}

TEST(LoadRigFromPath, MissingPathNamesIt) {
  try {
    loadRigFromPath("/nonexistent/rig.yaml");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/rig.yaml: no such file or folder"), std::string::npos)
        << e.what();
  }
}
