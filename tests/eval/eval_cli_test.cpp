#include <gtest/gtest.h>

#include <filesystem>

#include "mcslam/dataset/dataset.hpp"
#include "test_support.hpp"

using namespace mcslam;

namespace {

std::string tool() { return test::binPath("mcslam-eval"); }
std::string gt() { return test::dataPath("eval/tum_fr2_desk/groundtruth.txt"); }
std::string est() { return test::dataPath("eval/tum_fr2_desk/estimate_orb.txt"); }

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST(EvalCli, ApeTextMatchesEvosFr2DeskFigures) {
  std::string out;
  ASSERT_EQ(test::runCommand(tool() + " ape " + gt() + " " + est(), &out), 0) << out;
  EXPECT_TRUE(contains(out, "pairs        2174")) << out;
  EXPECT_TRUE(contains(out, "rmse         0.008119 m")) << out;
  EXPECT_TRUE(contains(out, "mean         0.007492 m")) << out;
  EXPECT_TRUE(contains(out, "median       0.007415 m")) << out;
  EXPECT_TRUE(contains(out, "std          0.003129 m")) << out;
  EXPECT_TRUE(contains(out, "min          0.000350 m")) << out;
  EXPECT_TRUE(contains(out, "max          0.024300 m")) << out;
  EXPECT_TRUE(contains(out, "path length")) << out;
  EXPECT_TRUE(contains(out, "rmse / path")) << out;
  EXPECT_FALSE(contains(out, "scale")) << out;
}

TEST(EvalCli, ApeJsonHasEveryFigureAndSim3AddsTheScale) {
  std::string out;
  ASSERT_EQ(test::runCommand(tool() + " ape " + gt() + " " + est() + " --align sim3 --json", &out), 0) << out;
  for (const char* key :
       {"\"metric\": \"ape\"", "\"rmse\":", "\"mean\":", "\"median\":", "\"std\":", "\"min\":", "\"max\":",
        "\"pairs\": 2174", "\"path_length\":", "\"rmse_percent\":", "\"scale\":", "\"align\": \"sim3\""}) {
    EXPECT_TRUE(contains(out, key)) << key << " missing in\n" << out;
  }
  EXPECT_EQ(out.front(), '{');
}

TEST(EvalCli, RpeTextAndJsonReportTranslationAndRotation) {
  std::string out;
  ASSERT_EQ(test::runCommand(tool() + " rpe " + gt() + " " + est() + " --delta 1 --delta-unit m", &out), 0) << out;
  EXPECT_TRUE(contains(out, "RPE for delta = 1 m")) << out;
  EXPECT_TRUE(contains(out, "translation (m)  rotation (deg)")) << out;
  ASSERT_EQ(test::runCommand(tool() + " rpe " + gt() + " " + est() + " --delta 10 --json", &out), 0) << out;
  for (const char* key : {"\"metric\": \"rpe\"", "\"delta\": 10", "\"delta_unit\": \"f\"",
                          "\"rmse\":", "\"rotation_deg\":", "\"path_length\":", "\"rmse_percent\":"}) {
    EXPECT_TRUE(contains(out, key)) << key << " missing in\n" << out;
  }
}

TEST(EvalCli, PlotWritesANonEmptyPng) {
  test::TempDir dir("eval-cli");
  const std::string png = dir.file("ape.png");
  std::string out;
  ASSERT_EQ(test::runCommand(tool() + " ape " + gt() + " " + est() + " --plot " + png, &out), 0) << out;
  ASSERT_TRUE(std::filesystem::exists(png));
  EXPECT_GT(std::filesystem::file_size(png), 10000u);
  const std::string rpe_png = dir.file("rpe.png");
  ASSERT_EQ(test::runCommand(tool() + " rpe " + gt() + " " + est() + " --plot " + rpe_png, &out), 0) << out;
  EXPECT_GT(std::filesystem::file_size(rpe_png), 10000u);
}

TEST(EvalCli, MissingFileExitsWith2AndNamesIt) {
  std::string out;
  EXPECT_EQ(test::runCommand(tool() + " ape /nonexistent/gt.txt " + est(), &out), 2);
  EXPECT_TRUE(contains(out, "mcslam-eval: /nonexistent/gt.txt: cannot open file")) << out;
}

TEST(EvalCli, MalformedLineExitsWith2AndNamesFileAndLine) {
  test::TempDir dir("eval-cli");
  const std::string bad =
      test::writeFile(dir.file("bad.txt"), "# t x y z qx qy qz qw\n1.0 0 0 0 0 0 0 1\n2.0 0 0 zero 0 0 0 1\n");
  std::string out;
  EXPECT_EQ(test::runCommand(tool() + " ape " + gt() + " " + bad, &out), 2);
  EXPECT_TRUE(contains(out, bad + ": line 3")) << out;
  EXPECT_TRUE(contains(out, "'zero'")) << out;
}

TEST(EvalCli, NoOverlappingTimestampsExitsWith2) {
  std::string out;
  EXPECT_EQ(test::runCommand(tool() + " ape " + gt() + " " + est() + " --t-offset 5000", &out), 2);
  EXPECT_TRUE(contains(out, "no matching timestamps")) << out;
  EXPECT_TRUE(contains(out, "estimate_orb.txt")) << out;
}

TEST(EvalCli, BadOptionValueExitsWith2AndHelpDocumentsTheOptions) {
  std::string out;
  EXPECT_EQ(test::runCommand(tool() + " ape " + gt() + " " + est() + " --align affine", &out), 2);
  EXPECT_TRUE(contains(out, "--align")) << out;
  ASSERT_EQ(test::runCommand(tool() + " rpe --help", &out), 0);
  for (const char* opt : {"--align", "--format", "--max-diff", "--plot", "--json", "--delta", "--delta-unit"}) {
    EXPECT_TRUE(contains(out, opt)) << opt << " not in help:\n" << out;
  }
}

TEST(EvalCli, KittiFormatWithIndexTimes) {
  test::TempDir dir("eval-cli");
  std::string gt_text, est_text;
  for (int i = 0; i < 6; ++i) {
    const double x = i, z = (i % 3) * 0.5;
    gt_text += "1 0 0 " + std::to_string(x) + " 0 1 0 0 0 0 1 " + std::to_string(z) + "\n";
    est_text += "1 0 0 " + std::to_string(x + 0.1) + " 0 1 0 0 0 0 1 " + std::to_string(z) + "\n";
  }
  const std::string g = test::writeFile(dir.file("gt.txt"), gt_text);
  const std::string e = test::writeFile(dir.file("est.txt"), est_text);
  std::string out;
  ASSERT_EQ(test::runCommand(tool() + " ape " + g + " " + e + " --format kitti --align none --json", &out), 0) << out;
  EXPECT_TRUE(contains(out, "\"pairs\": 6")) << out;
  EXPECT_TRUE(contains(out, "\"rmse\": 0.1")) << out;
}

TEST(EvalCli, ReferenceCanBeADatasetFolderWithGroundTruth) {
  test::TempDir dir("eval-cli");
  Trajectory gt, est;
  for (int i = 0; i < 10; ++i) {
    gt.push_back({1000000000LL * i, SE3(Mat3::Identity(), Vec3(i, 0.1 * i * i, 0))});
    est.push_back({1000000000LL * i + 2000000, SE3(Mat3::Identity(), Vec3(i, 0.1 * i * i, 0.25))});
  }
  Rig rig;
  rig.cameras.push_back({"cam0", CameraModel(8, 8, 10, 10, 3.5, 3.5, Distortion::None), SE3(), 0});
  {
    AslDatasetWriter w(dir.file("asl"), rig);
    w.writeGroundTruth(gt);
    w.close();
  }
  writeTumTrajectory(dir.file("est.txt"), est);
  std::string out;
  ASSERT_EQ(
      test::runCommand(tool() + " ape " + dir.file("asl") + " " + dir.file("est.txt") + " --align none --json", &out),
      0)
      << out;
  EXPECT_TRUE(contains(out, "\"pairs\": 10")) << out;
  EXPECT_TRUE(contains(out, "\"rmse\": 0.25")) << out;
  // A folder without ground truth is a clear error.
  std::filesystem::remove(dir.file("asl/groundtruth.txt"));
  EXPECT_EQ(test::runCommand(tool() + " ape " + dir.file("asl") + " " + dir.file("est.txt"), &out), 2);
  EXPECT_TRUE(contains(out, "the dataset has no ground truth")) << out;
}
