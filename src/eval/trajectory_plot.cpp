#include "mcslam/eval/trajectory_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "mcslam/core/error.hpp"
#include "plot_drawing.hpp"

namespace mcslam {

namespace {

using plot::Align;

// Maps the two chosen world axes into the plot rectangle with one scale (equal aspect).
struct View {
  int h = 0, v = 2;  // world axes shown horizontally and vertically
  cv::Rect area;
  double scale = 1;       // pixels per metre
  double h0 = 0, v0 = 0;  // world coordinates at the area's left and bottom edges
  double h1 = 0, v1 = 0;  // ... right and top edges
  cv::Point2d px(const Vec3& p) const {
    return {area.x + (p[h] - h0) * scale, area.y + area.height - (p[v] - v0) * scale};
  }
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
  view.area = area;
  const double span_h = std::max(extent[view.h], 1e-6), span_v = std::max(extent[view.v], 1e-6);
  const double pad = 1.08;  // a margin so that the path does not touch the frame
  view.scale = std::min(area.width / (span_h * pad), area.height / (span_v * pad));
  const double mid_h = 0.5 * (lo[view.h] + hi[view.h]), mid_v = 0.5 * (lo[view.v] + hi[view.v]);
  view.h0 = mid_h - 0.5 * area.width / view.scale;
  view.h1 = mid_h + 0.5 * area.width / view.scale;
  view.v0 = mid_v - 0.5 * area.height / view.scale;
  view.v1 = mid_v + 0.5 * area.height / view.scale;
  return view;
}

const char* axisName(int axis) { return axis == 0 ? "x" : axis == 1 ? "y" : "z"; }

void drawGrid(cv::Mat& img, const View& view) {
  const double step = plot::niceStep(110.0 / view.scale);
  const int decimals = plot::decimalsFor(step);
  const cv::Rect& a = view.area;
  for (double w = std::ceil(view.h0 / step) * step; w <= view.h1; w += step) {
    const int x = static_cast<int>(std::lround(a.x + (w - view.h0) * view.scale));
    cv::line(img, {x, a.y}, {x, a.y + a.height}, plot::kGrid, 1);
    cv::line(img, {x, a.y + a.height}, {x, a.y + a.height + 5}, plot::kAxis, 1);
    plot::text(img, plot::formatNumber(w, decimals), x, a.y + a.height + 24, 0.5, plot::kText, 1, Align::Centre);
  }
  for (double w = std::ceil(view.v0 / step) * step; w <= view.v1; w += step) {
    const int y = static_cast<int>(std::lround(a.y + a.height - (w - view.v0) * view.scale));
    cv::line(img, {a.x, y}, {a.x + a.width, y}, plot::kGrid, 1);
    cv::line(img, {a.x - 5, y}, {a.x, y}, plot::kAxis, 1);
    plot::text(img, plot::formatNumber(w, decimals), a.x - 9, y + 6, 0.5, plot::kText, 1, Align::Right);
  }
  cv::rectangle(img, a, plot::kAxis, 1);
  plot::text(img, std::string(axisName(view.h)) + " [m]", a.x + a.width / 2, a.y + a.height + 56, 0.65, plot::kText, 1,
             Align::Centre);
  plot::verticalText(img, std::string(axisName(view.v)) + " [m]", a.x - 72, a.y + a.height / 2, 0.65, plot::kText);
}

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

// Puts the legend in the corner of the plot area that covers the fewest trajectory points.
void drawLegend(cv::Mat& img, const View& view, const TrajectoryPlot& plot, const std::vector<Vec3>& all) {
  const std::array<std::string, 4> labels{plot.reference_label, plot.estimate_label, "start", "end"};
  int text_w = 0;
  for (const auto& l : labels) text_w = std::max(text_w, plot::textSize(l, 0.55).width);
  const cv::Size box(text_w + 78, 4 * 26 + 14);
  const cv::Rect& a = view.area;
  const int m = 12;
  const std::array<cv::Point, 4> corners{cv::Point(a.x + m, a.y + m), cv::Point(a.br().x - m - box.width, a.y + m),
                                         cv::Point(a.x + m, a.br().y - m - box.height),
                                         cv::Point(a.br().x - m - box.width, a.br().y - m - box.height)};
  std::size_t best = 0, best_count = std::numeric_limits<std::size_t>::max();
  for (std::size_t c = 0; c < corners.size(); ++c) {
    const cv::Rect r(corners[c], box);
    std::size_t count = 0;
    for (const Vec3& p : all) count += r.contains(view.px(p)) ? 1 : 0;
    if (count < best_count) {
      best = c;
      best_count = count;
    }
  }
  const cv::Rect r(corners[best], box);
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

  drawGrid(img, view);
  drawTrajectories(img, view, plot, range);
  const std::vector<Vec3>& marked = plot.estimate.empty() ? plot.reference : plot.estimate;
  startMarker(img, view.px(marked.front()));
  endMarker(img, view.px(marked.back()));
  drawLegend(img, view, plot, all);
  if (range.valid) {
    drawColourBar(img, cv::Rect(view.area.br().x + 32, view.area.y + 30, 22, view.area.height - 60), range,
                  plot.error_label);
  }
  plot::text(img, plot.title, width / 2, 42, 0.85, plot::kBlack, 1, Align::Centre);
  plot::text(img, plot.subtitle, width / 2, 74, 0.5, plot::kText, 1, Align::Centre);

  std::vector<uchar> png;
  if (!cv::imencode(".png", img, png)) throw InputError(png_path + ": cannot encode the plot as PNG");
  std::ofstream out(png_path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  if (!out) throw InputError(png_path + ": cannot write the plot");
}

}  // namespace mcslam
