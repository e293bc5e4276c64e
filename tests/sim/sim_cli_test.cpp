// mcslam-sim's command line: bad input gets a message naming what was wrong and exit code 2; --help documents
// every option; --preview writes a contact sheet of the written cameras.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "sim_cli_support.hpp"

namespace mcslam::sim {
namespace {

using testing::runSim;

// Runs a command line that must be refused; returns the message.
std::string refused(const std::string& args) {
  test::TempDir tmp("mcslam-sim-cli");
  std::string out;
  const int code = runSim(args + " --out " + tmp.file("out"), &out);
  EXPECT_EQ(code, 2) << args << "\n" << out;
  EXPECT_FALSE(std::filesystem::exists(tmp.file("out/camchain.yaml"))) << args << ": nothing may be written";
  return out;
}

TEST(SimCli, UnknownPresetIsNamedWithTheKnownOnes) {
  const std::string out = refused("--rig isek");
  EXPECT_NE(out.find("rig 'isek' is neither a preset"), std::string::npos) << out;
  EXPECT_NE(out.find("ring8"), std::string::npos) << out;
}

TEST(SimCli, MissingCalibrationFileIsNamed) {
  const std::string out = refused("--rig /nonexistent/camchain.yaml");
  EXPECT_NE(out.find("/nonexistent/camchain.yaml"), std::string::npos) << out;
}

TEST(SimCli, UnknownWorldIsNamedWithTheKnownOnes) {
  const std::string out = refused("--world moon");
  EXPECT_NE(out.find("unknown world 'moon'"), std::string::npos) << out;
  EXPECT_NE(out.find("courtyard"), std::string::npos) << out;
}

TEST(SimCli, MalformedCameraListIsNamed) {
  const std::string out = refused("--cameras 0,x");
  EXPECT_NE(out.find("--cameras"), std::string::npos) << out;
  EXPECT_NE(out.find("'x' is not a camera index"), std::string::npos) << out;
}

TEST(SimCli, CameraBeyondTheRigIsNamed) {
  const std::string out = refused("--rig stereo --cameras 0,2");
  EXPECT_NE(out.find("camera 2 does not exist"), std::string::npos) << out;
}

TEST(SimCli, BadNumbersAreNamed) {
  EXPECT_NE(refused("--rate 0").find("rate"), std::string::npos);
  EXPECT_NE(refused("--frames -3").find("frames"), std::string::npos);
  EXPECT_NE(refused("--motion-blur -1").find("--motion-blur"), std::string::npos);
  EXPECT_NE(refused("--preview-scale 0 --preview x.png").find("--preview-scale"), std::string::npos);
  EXPECT_NE(refused("--unknown-option").find("--unknown-option"), std::string::npos);
}

TEST(SimCli, HelpDocumentsEveryOption) {
  std::string out;
  ASSERT_EQ(runSim("--help", &out), 0);
  for (const char* option : {"--rig",
                             "--world",
                             "--trajectory",
                             "--frames",
                             "--rate",
                             "--seed",
                             "--out",
                             "--cameras",
                             "--moving-objects",
                             "--textures",
                             "--no-depth",
                             "--no-noise",
                             "--no-exposure-variation",
                             "--no-vignetting",
                             "--no-antialiasing",
                             "--motion-blur",
                             "--threads",
                             "--overwrite",
                             "--quiet",
                             "--preview",
                             "--preview-frame",
                             "--preview-scale"}) {
    EXPECT_NE(out.find(option), std::string::npos) << option;
  }
}

TEST(SimCli, PreviewWritesOneTilePerCameraAndNoDataset) {
  test::TempDir tmp("mcslam-sim-preview");
  const std::string sheet = tmp.file("sheet.png");
  std::string out;
  const std::string args = "--rig stereo --world corridor --quiet --preview-scale 0.25 --preview " + sheet;
  ASSERT_EQ(runSim(args, &out, tmp.path().string()), 0) << out;
  const cv::Mat img = cv::imread(sheet, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.type(), CV_8UC1);
  EXPECT_EQ(img.cols, 2 * 180 + 3 * 4);  // two 180x135 tiles side by side, 4 px gaps around and between them
  EXPECT_EQ(img.rows, 135 + 2 * 4);
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "mcslam_sim_out")) << "--preview alone writes no dataset";
}

TEST(SimCli, UnwritablePreviewIsNamed) {
  const std::string out = refused("--rig mono --world corridor --preview /nonexistent/dir/sheet.png");
  EXPECT_NE(out.find("/nonexistent/dir/sheet.png"), std::string::npos) << out;
}

}  // namespace
}  // namespace mcslam::sim
