#include "mcslam/eval/trajectory_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "mcslam/core/error.hpp"
#include "plot_drawing.hpp"
#include "plot_view.hpp"

namespace mcslam {

namespace {

using plot::Align;

// The two world axes shown, in a plane view.
struct View {
  int h = 0, v = 2;  // world axes shown horizontally and vertically
  plot::PlaneView plane;
  cv::Point2d px(const Vec3& p) const { return plane.px(p[h], p[v]); }
};

View makeView(const std::vector<Vec3>& pts, const cv::Rect& area) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& p : pts) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Vec3 extent = hi - lo;
  // The two axes of largest extent, shown in index order (x-z: x right, z up, the top view of a y-down frame).
  std::array<int, 3> order{0, 1, 2};
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return extent[a] > extent[b]; });
  View view;
  view.h = std::min(order[0], order[1]);
  view.v = std::max(order[0], order[1]);
  view.plane = plot::fitPlaneView({lo[view.h], lo[view.v]}, {hi[view.h], hi[view.v]}, area);
  return view;
}

const char* axisName(int axis) { return axis == 0 ? "x" : axis == 1 ? "y" : "z"; }

struct ErrorRange {
  double lo = 0, hi = 0;
  bool valid = false;
  double normalised(double e) const { return hi > lo ? (e - lo) / (hi - lo) : 0.5; }
};

ErrorRange errorRange(const std::vector<double>& errors) {
  ErrorRange r;
  for (double e : errors) {
    if (!std::isfinite(e)) continue;
    r.lo = r.valid ? std::min(r.lo, e) : e;
    r.hi = r.valid ? std::max(r.hi, e) : e;
    r.valid = true;
  }
  return r;
}

void drawTrajectories(cv::Mat& img, const View& view, const TrajectoryPlot& plot, const ErrorRange& range) {
  const auto errorAt = [&](std::size_t i) {
    return i < plot.estimate_error.size() ? plot.estimate_error[i] : std::numeric_limits<double>::quiet_NaN();
  };
  for (std::size_t i = 1; i < plot.estimate.size(); ++i) {
    const double e = 0.5 * (errorAt(i - 1) + errorAt(i));
    const cv::Scalar colour = range.valid && std::isfinite(e) ? plot::errorColour(range.normalised(e)) : plot::kGrey;
    cv::line(img, view.px(plot.estimate[i - 1]), view.px(plot.estimate[i]), colour, 3, cv::LINE_AA);
  }
  if (plot.estimate.size() == 1) {
    cv::circle(img, view.px(plot.estimate[0]), 3, plot::errorColour(0.5), cv::FILLED, cv::LINE_AA);
  }
  // The reference goes on top, thin, so that it stays visible where the estimate follows it closely.
  double phase = 0;
  for (std::size_t i = 1; i < plot.reference.size(); ++i) {
    plot::dashedLine(img, view.px(plot.reference[i - 1]), view.px(plot.reference[i]), plot::kReference, 1, 8, 5, phase);
  }
}

void startMarker(cv::Mat& img, cv::Point2d p) {
  cv::circle(img, p, 8, plot::kWhite, cv::FILLED, cv::LINE_AA);
  cv::circle(img, p, 8, plot::kBlack, 2, cv::LINE_AA);
}

void endMarker(cv::Mat& img, cv::Point2d p) {
  const cv::Point2d d(7, 7);
  cv::rectangle(img, p - d, p + d, plot::kBlack, cv::FILLED, cv::LINE_AA);
  cv::rectangle(img, p - d, p + d, plot::kWhite, 1, cv::LINE_AA);
}

void drawLegend(cv::Mat& img, const View& view, const TrajectoryPlot& plot, const std::vector<Vec3>& all) {
  const std::array<std::string, 4> labels{plot.reference_label, plot.estimate_label, "start", "end"};
  int text_w = 0;
  for (const auto& l : labels) text_w = std::max(text_w, plot::textSize(l, 0.55).width);
  const cv::Size box(text_w + 78, 4 * 26 + 14);
  std::vector<cv::Point2d> drawn;
  drawn.reserve(all.size());
  for (const Vec3& p : all) drawn.push_back(view.px(p));
  const cv::Rect r = plot::quietestCorner(view.plane, box, drawn);
  cv::rectangle(img, r, plot::kWhite, cv::FILLED);
  cv::rectangle(img, r, plot::kAxis, 1);
  const int x0 = r.x + 12, x1 = r.x + 54, tx = r.x + 66;
  int y = r.y + 24;
  double phase = 0;
  plot::dashedLine(img, cv::Point2d(x0, y - 5), cv::Point2d(x1, y - 5), plot::kReference, 1, 8, 5, phase);
  plot::text(img, labels[0], tx, y, 0.55, plot::kText);
  y += 26;
  for (int k = 0; k < 6; ++k) {  // a short stretch of the colour ramp
    const double u0 = x0 + (x1 - x0) * k / 6.0, u1 = x0 + (x1 - x0) * (k + 1) / 6.0;
    cv::line(img, cv::Point2d(u0, y - 5), cv::Point2d(u1, y - 5), plot::errorColour(k / 5.0), 3, cv::LINE_AA);
  }
  plot::text(img, labels[1], tx, y, 0.55, plot::kText);
  y += 26;
  startMarker(img, cv::Point2d((x0 + x1) / 2.0, y - 5));
  plot::text(img, labels[2], tx, y, 0.55, plot::kText);
  y += 26;
  endMarker(img, cv::Point2d((x0 + x1) / 2.0, y - 5));
  plot::text(img, labels[3], tx, y, 0.55, plot::kText);
}

void drawColourBar(cv::Mat& img, const cv::Rect& bar, const ErrorRange& range, const std::string& label) {
  for (int y = 0; y < bar.height; ++y) {
    const double v = 1.0 - static_cast<double>(y) / std::max(1, bar.height - 1);
    cv::line(img, {bar.x, bar.y + y}, {bar.x + bar.width - 1, bar.y + y}, plot::errorColour(v), 1);
  }
  cv::rectangle(img, bar, plot::kAxis, 1);
  const double span = range.hi - range.lo;
  const double step = plot::niceStep(span > 0 ? span / 6 : std::max(range.hi, 1e-3));
  const int decimals = plot::decimalsFor(step);
  const auto yOf = [&](double e) { return bar.y + bar.height - 1 - range.normalised(e) * (bar.height - 1); };
  const int x = bar.x + bar.width;
  if (span > 0) {
    for (double e = std::ceil(range.lo / step) * step; e <= range.hi + 1e-12; e += step) {
      const int y = static_cast<int>(std::lround(yOf(e)));
      cv::line(img, {x, y}, {x + 5, y}, plot::kAxis, 1);
      plot::text(img, plot::formatNumber(e, decimals), x + 9, y + 5, 0.45, plot::kText);
    }
  } else {
    plot::text(img, plot::formatNumber(range.lo, decimals + 1), x + 9, bar.y + bar.height / 2 + 5, 0.45, plot::kText);
  }
  plot::text(img, label, bar.x + bar.width / 2, bar.y - 14, 0.5, plot::kText, 1, Align::Centre);
}

}  // namespace

void writeTrajectoryPlot(const std::string& png_path, const TrajectoryPlot& plot, int width, int height) {
  std::vector<Vec3> all = plot.reference;
  all.insert(all.end(), plot.estimate.begin(), plot.estimate.end());
  if (all.empty()) throw InputError(png_path + ": nothing to plot (both trajectories are empty)");

  cv::Mat img(height, width, CV_8UC3, plot::kWhite);
  const ErrorRange range = errorRange(plot.estimate_error);
  const int right = range.valid ? 150 : 40;
  const View view = makeView(all, cv::Rect(100, 96, width - 100 - right, height - 96 - 80));

  plot::drawPlaneGrid(img, view.plane, std::string(axisName(view.h)) + " [m]", std::string(axisName(view.v)) + " [m]");
  drawTrajectories(img, view, plot, range);
  const std::vector<Vec3>& marked = plot.estimate.empty() ? plot.reference : plot.estimate;
  startMarker(img, view.px(marked.front()));
  endMarker(img, view.px(marked.back()));
  drawLegend(img, view, plot, all);
  if (range.valid) {
    drawColourBar(img, cv::Rect(view.plane.area.br().x + 32, view.plane.area.y + 30, 22, view.plane.area.height - 60),
                  range, plot.error_label);
  }
  plot::text(img, plot.title, width / 2, 42, 0.85, plot::kBlack, 1, Align::Centre);
  plot::text(img, plot.subtitle, width / 2, 74, 0.5, plot::kText, 1, Align::Centre);

  plot::writePng(png_path, img);
}

}  // namespace mcslam
