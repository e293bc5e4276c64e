// mcslam-rig as a user runs it: info, perturb and compare round trip, errors exit 2 with the reason.
#include <gtest/gtest.h>

#include "test_support.hpp"

using namespace mcslam;

namespace {
std::string rigTool() { return test::binPath("mcslam-rig"); }
std::string isecPath() { return test::dataPath("calib/isec_5cam_camchain.yaml"); }
// Runs of spaces become one, so the checks do not depend on column widths.
std::string squeezed(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == ' ' && !out.empty() && out.back() == ' ') continue;
    out += c;
  }
  return out;
}
}  // namespace

TEST(RigCli, InfoJsonListsEveryCamera) {
  std::string out;
  ASSERT_EQ(test::runCommand(rigTool() + " info --json " + isecPath(), &out), 0) << out;
  for (int i = 0; i < 5; ++i) EXPECT_NE(out.find("\"index\": " + std::to_string(i)), std::string::npos) << out;
  EXPECT_NE(out.find("\"direction\""), std::string::npos);
}

TEST(RigCli, PerturbThenCompareGivesTheErrorBack) {
  test::TempDir dir("rig_cli");
  const std::string moved = dir.file("moved.yaml");
  std::string out;
  ASSERT_EQ(test::runCommand(
                rigTool() + " perturb " + isecPath() + " --camera 3 --translation 0.02 --rotation-deg 1 --out " + moved,
                &out),
            0)
      << out;
  ASSERT_EQ(test::runCommand(rigTool() + " compare " + isecPath() + " " + moved, &out), 0) << out;
  EXPECT_NE(squeezed(out).find("cam3 20.00 1.0000"), std::string::npos) << out;
  EXPECT_NE(squeezed(out).find("cam2 0.00 0.0000"), std::string::npos) << out;
}

TEST(RigCli, BadCameraAndMismatchedRigsAreExplained) {
  test::TempDir dir("rig_cli");
  std::string out;
  EXPECT_EQ(test::runCommand(rigTool() + " perturb " + isecPath() + " --camera 7 --out " + dir.file("x.yaml"), &out),
            2);
  EXPECT_NE(out.find("--camera 7: the rig has cameras 0..4"), std::string::npos) << out;
  EXPECT_EQ(
      test::runCommand(
          rigTool() + " compare " + isecPath() + " " + test::dataPath("calib/euroc_kalibr_imucam_chain.yaml"), &out),
      2);
  EXPECT_NE(out.find("the calibrations have 5 and 2 cameras"), std::string::npos) << out;
}
