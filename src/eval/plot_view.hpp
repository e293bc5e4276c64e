#pragma once
// The area of a plot that shows a plane with one scale on both axes (metres), its grid, and writing the image.
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace mcslam::plot {

struct PlaneView {
  cv::Rect area;
  double scale = 1;       // pixels per metre
  double h0 = 0, v0 = 0;  // plane coordinates at the area's left and bottom edges
  double h1 = 0, v1 = 0;  // ... right and top edges
  cv::Point2d px(double h, double v) const {
    return {area.x + (h - h0) * scale, area.y + area.height - (v - v0) * scale};
  }
  cv::Point2d px(const Eigen::Vector2d& p) const { return px(p.x(), p.y()); }
  bool shows(const Eigen::Vector2d& p) const { return p.x() >= h0 && p.x() <= h1 && p.y() >= v0 && p.y() <= v1; }
};

// The view that shows the box [lo, hi] whole in `area`, centred, with a small margin.
PlaneView fitPlaneView(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, const cv::Rect& area);

// Grid lines at round steps, their values, the frame and the axis captions.
void drawPlaneGrid(cv::Mat& img, const PlaneView& view, const std::string& h_caption, const std::string& v_caption);

// Where a legend of `box` covers the fewest of the `drawn` pixels: one of the area's four corners.
cv::Rect quietestCorner(const PlaneView& view, cv::Size box, const std::vector<cv::Point2d>& drawn);

// Throws InputError naming the path when the PNG cannot be encoded or written.
void writePng(const std::string& path, const cv::Mat& img);

}  // namespace mcslam::plot
