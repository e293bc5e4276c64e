#include "plot_view.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "mcslam/core/error.hpp"
#include "plot_drawing.hpp"

namespace mcslam::plot {

PlaneView fitPlaneView(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, const cv::Rect& area) {
  PlaneView view;
  view.area = area;
  // A span under a millionth of the coordinates' size would make grid steps the doubles cannot add.
  const double floor = std::max(1e-6, 1e-6 * std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff()));
  const double span_h = std::max(hi.x() - lo.x(), floor), span_v = std::max(hi.y() - lo.y(), floor);
  const double pad = 1.08;  // a margin so that nothing touches the frame
  view.scale = std::min(area.width / (span_h * pad), area.height / (span_v * pad));
  const double mid_h = 0.5 * (lo.x() + hi.x()), mid_v = 0.5 * (lo.y() + hi.y());
  view.h0 = mid_h - 0.5 * area.width / view.scale;
  view.h1 = mid_h + 0.5 * area.width / view.scale;
  view.v0 = mid_v - 0.5 * area.height / view.scale;
  view.v1 = mid_v + 0.5 * area.height / view.scale;
  return view;
}

void drawPlaneGrid(cv::Mat& img, const PlaneView& view, const std::string& h_caption, const std::string& v_caption) {
  const double step = niceStep(110.0 / view.scale);
  const int decimals = decimalsFor(step);
  const cv::Rect& a = view.area;
  for (double k = std::ceil(view.h0 / step); k * step <= view.h1; ++k) {
    const double w = k * step;
    const int x = static_cast<int>(std::lround(a.x + (w - view.h0) * view.scale));
    cv::line(img, {x, a.y}, {x, a.y + a.height}, kGrid, 1);
    cv::line(img, {x, a.y + a.height}, {x, a.y + a.height + 5}, kAxis, 1);
    text(img, formatNumber(w, decimals), x, a.y + a.height + 24, 0.5, kText, 1, Align::Centre);
  }
  for (double k = std::ceil(view.v0 / step); k * step <= view.v1; ++k) {
    const double w = k * step;
    const int y = static_cast<int>(std::lround(a.y + a.height - (w - view.v0) * view.scale));
    cv::line(img, {a.x, y}, {a.x + a.width, y}, kGrid, 1);
    cv::line(img, {a.x - 5, y}, {a.x, y}, kAxis, 1);
    text(img, formatNumber(w, decimals), a.x - 9, y + 6, 0.5, kText, 1, Align::Right);
  }
  cv::rectangle(img, a, kAxis, 1);
  text(img, h_caption, a.x + a.width / 2, a.y + a.height + 56, 0.65, kText, 1, Align::Centre);
  verticalText(img, v_caption, a.x - 72, a.y + a.height / 2, 0.65, kText);
}

cv::Rect quietestCorner(const PlaneView& view, cv::Size box, const std::vector<cv::Point2d>& drawn) {
  const cv::Rect& a = view.area;
  const int m = 12;
  const std::array<cv::Point, 4> corners{cv::Point(a.x + m, a.y + m), cv::Point(a.br().x - m - box.width, a.y + m),
                                         cv::Point(a.x + m, a.br().y - m - box.height),
                                         cv::Point(a.br().x - m - box.width, a.br().y - m - box.height)};
  std::size_t best = 0, best_count = std::numeric_limits<std::size_t>::max();
  for (std::size_t c = 0; c < corners.size(); ++c) {
    const cv::Rect r(corners[c], box);
    const auto count = static_cast<std::size_t>(
        std::count_if(drawn.begin(), drawn.end(), [&](const cv::Point2d& p) { return r.contains(p); }));
    if (count < best_count) {
      best = c;
      best_count = count;
    }
  }
  return {corners[best], box};
}

void writePng(const std::string& path, const cv::Mat& img) {
  std::vector<uchar> png;
  if (!cv::imencode(".png", img, png)) throw InputError(path + ": cannot encode the plot as PNG");
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  out.flush();  // a full disk shows only when the buffer goes out
  if (!out) throw InputError(path + ": cannot write the plot");
}

}  // namespace mcslam::plot
