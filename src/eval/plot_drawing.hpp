#pragma once
// Small drawing helpers for the evaluation plots (OpenCV has lines and text, nothing like a plot library).
#include <opencv2/core.hpp>
#include <string>

namespace mcslam::plot {

// Colours (BGR).
const cv::Scalar kBlack(30, 30, 30);
const cv::Scalar kText(40, 40, 40);
const cv::Scalar kGrey(140, 140, 140);
const cv::Scalar kReference(70, 70, 70);
const cv::Scalar kGrid(228, 228, 228);
const cv::Scalar kAxis(120, 120, 120);
const cv::Scalar kWhite(255, 255, 255);

enum class Align { Left, Centre, Right };

// Text with its baseline at y, anchored at x as asked. Returns the text width in pixels.
int text(cv::Mat& img, const std::string& s, int x, int y, double scale, const cv::Scalar& colour, int thickness = 1,
         Align align = Align::Left);
cv::Size textSize(const std::string& s, double scale, int thickness = 1);
// Text turned 90 degrees counter-clockwise (reads bottom to top), centred on (cx, cy).
void verticalText(cv::Mat& img, const std::string& s, int cx, int cy, double scale, const cv::Scalar& colour);

// A dashed segment; `phase` carries the dash pattern from one segment to the next (pixels).
void dashedLine(cv::Mat& img, cv::Point2d a, cv::Point2d b, const cv::Scalar& colour, int thickness, double dash,
                double gap, double& phase);

// Colour of a value in [0, 1] on the plots' error colour map.
cv::Scalar errorColour(double v);

// A round tick step (1, 2 or 5 times a power of ten) close to `raw`.
double niceStep(double raw);
// Decimals needed to print multiples of `step` exactly.
int decimalsFor(double step);
std::string formatNumber(double v, int decimals);

}  // namespace mcslam::plot
