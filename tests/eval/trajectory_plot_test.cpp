#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "mcslam/core/error.hpp"
#include "mcslam/eval/trajectory_plot.hpp"
#include "test_support.hpp"

using namespace mcslam;

namespace {

TrajectoryPlot circlePlot() {
  TrajectoryPlot p;
  p.title = "APE test";
  for (int i = 0; i <= 100; ++i) {
    const double a = 2 * M_PI * i / 100;
    p.reference.emplace_back(std::cos(a), 0.0, std::sin(a));  // x-z plane: the top view of a y-down world
    p.estimate.emplace_back(1.05 * std::cos(a), 0.01, 1.05 * std::sin(a));
    p.estimate_error.push_back(0.05 + 0.01 * std::sin(a));
  }
  return p;
}

// Pixels noticeably coloured (not grey/white/black): the estimate and the colour bar.
int colouredPixels(const cv::Mat& img) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) {
      const cv::Vec3b c = img.at<cv::Vec3b>(y, x);
      const int spread = std::max({c[0], c[1], c[2]}) - std::min({c[0], c[1], c[2]});
      n += spread > 60 ? 1 : 0;
    }
  }
  return n;
}

}  // namespace

TEST(TrajectoryPlot, WritesAPngOfTheRequestedSizeWithAColouredEstimate) {
  test::TempDir dir("plot");
  const std::string path = dir.file("top.png");
  writeTrajectoryPlot(path, circlePlot(), 800, 600);
  const cv::Mat img = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.cols, 800);
  EXPECT_EQ(img.rows, 600);
  EXPECT_GT(colouredPixels(img), 2000);
}

TEST(TrajectoryPlot, WithoutErrorsTheEstimateIsGreyAndThereIsNoColourBar) {
  test::TempDir dir("plot");
  TrajectoryPlot p = circlePlot();
  p.estimate_error.clear();
  writeTrajectoryPlot(dir.file("plain.png"), p, 800, 600);
  const cv::Mat img = cv::imread(dir.file("plain.png"), cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  EXPECT_LT(colouredPixels(img), 300);  // only the small colour ramp in the legend
}

TEST(TrajectoryPlot, ErrorsNameThePath) {
  test::TempDir dir("plot");
  const std::string bad = dir.file("no/such/folder/p.png");
  try {
    writeTrajectoryPlot(bad, circlePlot());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
  EXPECT_THROW(writeTrajectoryPlot(dir.file("empty.png"), TrajectoryPlot{}), InputError);
}
