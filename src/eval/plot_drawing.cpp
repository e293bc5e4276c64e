#include "plot_drawing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace mcslam::plot {

namespace {
constexpr int kFont = cv::FONT_HERSHEY_DUPLEX;
}

cv::Size textSize(const std::string& s, double scale, int thickness) {
  int baseline = 0;
  return cv::getTextSize(s, kFont, scale, thickness, &baseline);
}

int text(cv::Mat& img, const std::string& s, int x, int y, double scale, const cv::Scalar& colour, int thickness,
         Align align) {
  const int w = textSize(s, scale, thickness).width;
  const int x0 = align == Align::Left ? x : align == Align::Centre ? x - w / 2 : x - w;
  cv::putText(img, s, cv::Point(x0, y), kFont, scale, colour, thickness, cv::LINE_AA);
  return w;
}

void verticalText(cv::Mat& img, const std::string& s, int cx, int cy, double scale, const cv::Scalar& colour) {
  const cv::Size sz = textSize(s, scale);
  cv::Mat patch(sz.height * 2 + 4, sz.width + 4, img.type(), kWhite);
  cv::putText(patch, s, cv::Point(2, sz.height + 2), kFont, scale, colour, 1, cv::LINE_AA);
  cv::Mat turned;
  cv::rotate(patch, turned, cv::ROTATE_90_COUNTERCLOCKWISE);
  const cv::Rect where(cx - turned.cols / 2, cy - turned.rows / 2, turned.cols, turned.rows);
  const cv::Rect inside = where & cv::Rect(0, 0, img.cols, img.rows);
  if (inside.area() > 0) turned(inside - where.tl()).copyTo(img(inside));
}

void dashedLine(cv::Mat& img, cv::Point2d a, cv::Point2d b, const cv::Scalar& colour, int thickness, double dash,
                double gap, double& phase) {
  const double len = cv::norm(b - a);
  if (len <= 0) return;
  const cv::Point2d dir = (b - a) / len;
  const double period = dash + gap;
  double s = 0;
  while (s < len) {
    const double in_period = std::fmod(phase + s, period);
    const bool on = in_period < dash;
    const double step = std::min(len - s, on ? dash - in_period : period - in_period);
    if (on) {
      cv::line(img, cv::Point2d(a + dir * s), cv::Point2d(a + dir * (s + step)), colour, thickness, cv::LINE_AA);
    }
    s += step;
  }
  phase = std::fmod(phase + len, period);
}

cv::Scalar errorColour(double v) {
  // A blue -> teal -> yellow -> orange -> dark red ramp: every part stays visible on white, and the
  // order reads as "worse" without a legend.
  static const double kStops[][3] = {
      // RGB
      {49, 54, 149}, {69, 117, 180}, {116, 173, 209}, {102, 189, 99}, {240, 200, 40}, {244, 109, 67}, {165, 0, 38}};
  constexpr int kN = sizeof(kStops) / sizeof(kStops[0]);
  v = std::clamp(std::isfinite(v) ? v : 0.0, 0.0, 1.0) * (kN - 1);
  const int i = std::min(static_cast<int>(v), kN - 2);
  const double f = v - i;
  double rgb[3];
  for (int c = 0; c < 3; ++c) rgb[c] = kStops[i][c] * (1 - f) + kStops[i + 1][c] * f;
  return cv::Scalar(rgb[2], rgb[1], rgb[0]);
}

double niceStep(double raw) {
  if (!(raw > 0) || !std::isfinite(raw)) return 1.0;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  const double m = raw / p;
  return (m < 1.5 ? 1.0 : m < 3.5 ? 2.0 : m < 7.5 ? 5.0 : 10.0) * p;
}

int decimalsFor(double step) { return std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9))); }

std::string formatNumber(double v, int decimals) {
  char buf[64];
  if (std::abs(v) < 0.5 * std::pow(10.0, -decimals)) v = 0.0;  // no "-0.0"
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

}  // namespace mcslam::plot
