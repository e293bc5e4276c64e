// tools/study/camera_study.py, the camera-configuration study, on a short rendered stereo sequence: a run of its
// repeats at the configured feature count is the plain mcslam-run (the variant configuration is the effective one
// with only the capacity changed), and the table reports each configuration once with its repeats.
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <sstream>

#include "test_support.hpp"

using namespace mcslam;

namespace {

std::string bin(const std::string& tool) { return test::binPath(tool); }
std::string study() { return std::string(MCSLAM_SOURCE_DIR) + "/tools/study/camera_study.py"; }

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int count(const std::string& text, const std::string& part) {
  int n = 0;
  for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

class CameraStudy : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDir>("camera_study");
    std::string out;
    ASSERT_EQ(test::runCommand(bin("mcslam-sim") + " --rig " + test::dataPath("calib/rectified_stereo_camchain.yaml") +
                                   " --world indoor --frames 30 --no-depth --quiet --seed 3 --out " + dir_->file("seq"),
                               &out),
              0)
        << out;
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::string runStudy(const std::string& args, int* code = nullptr) {
    std::string out;
    const int c = test::runCommand(
        "python3 " + study() + " --bin " + test::binPath("") + " --dataset " + dir_->file("seq") + " " + args + " 2>&1",
        &out);
    if (code) *code = c;
    return out;
  }
  static std::unique_ptr<test::TempDir> dir_;
};

std::unique_ptr<test::TempDir> CameraStudy::dir_;

}  // namespace

TEST_F(CameraStudy, RepeatsSpreadTheFeatureCountAndTheMiddleRunIsThePlainRun) {
  if (test::runCommand("python3 --version") != 0) GTEST_SKIP() << "python3 is not installed";
  const std::string out_dir = dir_->file("repeats");
  int code = -1;
  const std::string out = runStudy("--config 'stereo=0,1' --repeats 3 --out " + out_dir, &code);
  ASSERT_EQ(code, 0) << out;

  // Three runs at 950, 1000 and 1050 features per camera, each with its own configuration file.
  const std::string json = readFile(out_dir + "/study.json");
  for (const char* f : {"950", "1000", "1050"}) {
    EXPECT_EQ(count(json, std::string("\"features_per_camera\": ") + f), 1) << f << " in\n" << json;
    EXPECT_NE(readFile(out_dir + "/seq_stereo_f" + f + ".yaml").find(std::string("max_features_per_camera: ") + f),
              std::string::npos)
        << f;
  }
  // One table row for the configuration, with its runs and their feature range; each run's loop-corrected
  // keyframes are evaluated too.
  const std::string table = readFile(out_dir + "/study.md");
  EXPECT_EQ(count(table, "| seq | stereo | 0,1 | 3 (950-1050) | "), 1) << table;
  EXPECT_EQ(count(table, "keyframes ATE (m), mean (min-max); runs with a loop closure"), 1) << table;
  EXPECT_EQ(count(json, "\"keyframes_ate_m\": "), 3) << json;
  EXPECT_FALSE(readFile(out_dir + "/seq_stereo_f1000_keyframes.tum").empty());

  // The run at the configured count is mcslam-run on defaults, pose for pose.
  const std::string plain = dir_->file("plain.tum");
  std::string run_out;
  ASSERT_EQ(
      test::runCommand(bin("mcslam-run") + " --dataset " + dir_->file("seq") + " --cameras 0,1 --quiet --out " + plain,
                       &run_out),
      0)
      << run_out;
  const std::string expected = readFile(plain);
  ASSERT_FALSE(expected.empty());
  EXPECT_EQ(readFile(out_dir + "/seq_stereo_f1000.tum"), expected);
}

TEST_F(CameraStudy, ZeroRepeatsIsAClearError) {
  if (test::runCommand("python3 --version") != 0) GTEST_SKIP() << "python3 is not installed";
  int code = 0;
  const std::string out = runStudy("--config 'stereo=0,1' --repeats 0 --out " + dir_->file("none"), &code);
  EXPECT_NE(code, 0);
  EXPECT_NE(out.find("--repeats 0: expected 1 or more"), std::string::npos) << out;
}
