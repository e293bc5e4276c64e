#include "mcslam/eval/map_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "mcslam/core/error.hpp"
#include "mcslam/eval/error_stats.hpp"
#include "plot_drawing.hpp"
#include "plot_view.hpp"

namespace mcslam {

namespace {

using plot::Align;

// Paths in the categorical colours of common plotting tools (BGR), red left out: it marks loops.
constexpr std::array<std::array<int, 3>, 8> kPathColours{{{180, 119, 31},
                                                          {14, 127, 255},
                                                          {44, 160, 44},
                                                          {189, 103, 148},
                                                          {75, 86, 140},
                                                          {194, 119, 227},
                                                          {34, 189, 188},
                                                          {207, 190, 23}}};
const cv::Scalar kLoop(40, 39, 214);

cv::Scalar pathColour(std::size_t i) {
  const auto& c = kPathColours[i % kPathColours.size()];
  return {static_cast<double>(c[0]), static_cast<double>(c[1]), static_cast<double>(c[2])};
}

// The box shown: every keyframe, and the points but their outermost 2% on each axis.
plot::PlaneView viewOf(const MapPlot& plot, const cv::Rect& area) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const MapPlot::Path& path : plot.paths) {
    for (const Eigen::Vector2d& k : path.keyframes) {
      lo = lo.cwiseMin(k);
      hi = hi.cwiseMax(k);
    }
  }
  if (!plot.points.empty()) {
    for (int axis = 0; axis < 2; ++axis) {
      std::vector<double> v;
      v.reserve(plot.points.size());
      for (const Eigen::Vector2d& p : plot.points) v.push_back(p[axis]);
      const auto [a, b] = centralRange(std::move(v), 0.02);
      lo[axis] = std::min(lo[axis], a);
      hi[axis] = std::max(hi[axis], b);
    }
  }
  return plot::fitPlaneView(lo, hi, area);
}

// Points as a density: a pixel darkens with the number of points in it, so that walls stand out from clutter.
void drawPoints(cv::Mat& img, const plot::PlaneView& view, const std::vector<Eigen::Vector2d>& points) {
  cv::Mat count = cv::Mat::zeros(img.size(), CV_32F);
  for (const Eigen::Vector2d& p : points) {
    if (!view.shows(p)) continue;
    const cv::Point2d q = view.px(p);
    const int x = static_cast<int>(q.x), y = static_cast<int>(q.y);
    if (x >= 0 && y >= 0 && x < img.cols && y < img.rows) count.at<float>(y, x) += 1.0f;
  }
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) {
      const float c = count.at<float>(y, x);
      if (c <= 0) continue;
      const double shade = std::min(1.0, 0.45 + 0.2 * std::log2(static_cast<double>(c)));
      const auto level = static_cast<uchar>(std::lround(235 - 150 * shade));
      img.at<cv::Vec3b>(y, x) = cv::Vec3b(level, level, level);
    }
  }
}

void drawPaths(cv::Mat& img, const plot::PlaneView& view, const MapPlot& plot) {
  for (const auto& [a, b] : plot.loops) cv::line(img, view.px(a), view.px(b), kLoop, 2, cv::LINE_AA);
  for (std::size_t i = 0; i < plot.paths.size(); ++i) {
    const std::vector<Eigen::Vector2d>& k = plot.paths[i].keyframes;
    const cv::Scalar colour = pathColour(i);
    for (std::size_t j = 1; j < k.size(); ++j) cv::line(img, view.px(k[j - 1]), view.px(k[j]), colour, 2, cv::LINE_AA);
    for (const Eigen::Vector2d& p : k) cv::circle(img, view.px(p), 3, colour, cv::FILLED, cv::LINE_AA);
    if (!k.empty()) {  // the segment's first keyframe
      cv::circle(img, view.px(k.front()), 8, plot::kWhite, cv::FILLED, cv::LINE_AA);
      cv::circle(img, view.px(k.front()), 8, colour, 3, cv::LINE_AA);
    }
  }
}

std::vector<cv::Point2d> drawnPixels(const plot::PlaneView& view, const MapPlot& plot) {
  std::vector<cv::Point2d> drawn;
  for (const MapPlot::Path& path : plot.paths)
    for (const Eigen::Vector2d& k : path.keyframes) drawn.push_back(view.px(k));
  for (const Eigen::Vector2d& p : plot.points)
    if (view.shows(p)) drawn.push_back(view.px(p));
  return drawn;
}

// One line per path (the first few, then how many more), the loops, the points.
void drawLegend(cv::Mat& img, const plot::PlaneView& view, const MapPlot& plot) {
  constexpr std::size_t kListed = 8;
  std::vector<std::string> labels;
  for (std::size_t i = 0; i < std::min(plot.paths.size(), kListed); ++i) labels.push_back(plot.paths[i].label);
  if (plot.paths.size() > kListed) labels.push_back("... " + std::to_string(plot.paths.size() - kListed) + " more");
  labels.push_back(std::to_string(plot.loops.size()) + (plot.loops.size() == 1 ? " loop" : " loops"));
  labels.push_back(std::to_string(plot.points.size()) + " points");
  int text_w = 0;
  for (const std::string& l : labels) text_w = std::max(text_w, plot::textSize(l, 0.55).width);
  const cv::Size box(text_w + 78, static_cast<int>(labels.size()) * 26 + 14);
  const cv::Rect r = plot::quietestCorner(view, box, drawnPixels(view, plot));
  cv::rectangle(img, r, plot::kWhite, cv::FILLED);
  cv::rectangle(img, r, plot::kAxis, 1);
  const int x0 = r.x + 12, x1 = r.x + 54, tx = r.x + 66;
  int y = r.y + 24;
  for (std::size_t i = 0; i < labels.size(); ++i, y += 26) {
    const std::size_t loops_row = labels.size() - 2, points_row = labels.size() - 1;
    if (i == points_row) {
      for (int k = 0; k < 5; ++k) cv::circle(img, cv::Point(x0 + 4 + 8 * k, y - 5 + (k % 2) * 3), 1, plot::kGrey, 2);
    } else {
      const cv::Scalar colour = i == loops_row ? kLoop : i < kListed ? pathColour(i) : plot::kGrey;
      cv::line(img, cv::Point(x0, y - 5), cv::Point(x1, y - 5), colour, 2, cv::LINE_AA);
    }
    plot::text(img, labels[i], tx, y, 0.55, plot::kText);
  }
}

}  // namespace

void writeMapPlot(const std::string& png_path, const MapPlot& plot, int width, int height) {
  const bool any =
      std::any_of(plot.paths.begin(), plot.paths.end(), [](const auto& p) { return !p.keyframes.empty(); });
  if (!any) throw InputError(png_path + ": nothing to plot (the map has no keyframe)");
  cv::Mat img(height, width, CV_8UC3, plot::kWhite);
  const plot::PlaneView view = viewOf(plot, cv::Rect(100, 96, width - 100 - 40, height - 96 - 80));
  plot::drawPlaneGrid(img, view, plot.h_caption, plot.v_caption);
  drawPoints(img, view, plot.points);
  drawPaths(img, view, plot);
  drawLegend(img, view, plot);
  plot::text(img, plot.title, width / 2, 42, 0.85, plot::kBlack, 1, Align::Centre);
  plot::text(img, plot.subtitle, width / 2, 74, 0.5, plot::kText, 1, Align::Centre);
  plot::writePng(png_path, img);
}

}  // namespace mcslam
