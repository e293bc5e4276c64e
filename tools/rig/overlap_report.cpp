#include "overlap_report.hpp"

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "mcslam/core/error.hpp"
#include "mcslam/core/json_writer.hpp"

namespace mcslam::rigtool {

void printOverlapText(const Rig& rig, const OverlapMap& map) {
  const OverlapOptions& o = map.options();
  std::printf("overlap for scene depths %.2f .. %.1f m, cells of %d px\n", o.min_depth, o.max_depth, o.cell_size_px);
  if (map.overlappingPairs().empty()) std::printf("  no camera pair overlaps (non-overlapping rig)\n");
  for (const auto& [i, j] : map.overlappingPairs()) {
    std::printf("  cam%d - cam%d   %5.1f%% of cam%d sees into cam%d, %5.1f%% of cam%d sees into cam%d\n", i, j,
                100.0 * map.overlapFraction(i, j), i, j, 100.0 * map.overlapFraction(j, i), j, i);
  }
  for (int c = 0; c < rig.size(); ++c) {
    bool any = false;
    for (int k = 0; k < rig.size(); ++k) any = any || map.overlaps(c, k) || map.overlaps(k, c);
    if (!any) std::printf("  cam%d overlaps no other camera\n", c);
  }
}

void printOverlapJson(const Rig& rig, const OverlapMap& map) {
  JsonWriter j(std::cout);
  j.beginObject();
  j.key("min_depth").value(map.options().min_depth);
  j.key("max_depth").value(map.options().max_depth);
  j.key("cell_size_px").value(map.options().cell_size_px);
  j.key("pairs").beginArray();
  for (const auto& [a, b] : map.overlappingPairs()) {
    j.beginObject();
    j.key("cameras").beginArray().value(a).value(b).endArray();
    j.key("fraction").beginArray().value(map.overlapFraction(a, b)).value(map.overlapFraction(b, a)).endArray();
    j.endObject();
  }
  j.endArray();
  j.key("fraction_matrix").beginArray();
  for (int a = 0; a < rig.size(); ++a) {
    j.beginArray();
    for (int b = 0; b < rig.size(); ++b) j.value(a == b ? 1.0 : map.overlapFraction(a, b));
    j.endArray();
  }
  j.endArray();
  j.endObject();
}

namespace {

void drawGrid(cv::Mat& canvas, const CellGrid& g, int x0, const std::vector<cv::Scalar>& colours) {
  for (int c = 0; c < g.cells(); ++c) {
    const int cx = c % g.cols, cy = c / g.cols;
    const cv::Rect r(x0 + cx * g.cell_size, cy * g.cell_size, std::min(g.cell_size, g.width - cx * g.cell_size),
                     std::min(g.cell_size, g.height - cy * g.cell_size));
    cv::rectangle(canvas, r, colours[c], cv::FILLED);
    cv::rectangle(canvas, r, cv::Scalar(90, 90, 90), 1);
  }
}

}  // namespace

int writeOverlapPngs(const Rig& rig, const OverlapMap& map, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create folder: " + ec.message());
  int written = 0;
  const cv::Scalar none(40, 40, 40), seen(70, 140, 70), example(40, 40, 230), reach(60, 170, 230);
  for (int i = 0; i < rig.size(); ++i) {
    for (int j = 0; j < rig.size(); ++j) {
      if (!map.overlaps(i, j)) continue;
      const CellGrid& gi = map.grid(i);
      const CellGrid& gj = map.grid(j);
      const int gap = 30, top = 40;
      cv::Mat canvas(std::max(gi.height, gj.height) + top, gi.width + gap + gj.width, CV_8UC3,
                     cv::Scalar(255, 255, 255));
      cv::Mat body = canvas(cv::Rect(0, top, canvas.cols, canvas.rows - top));
      std::vector<cv::Scalar> ci(gi.cells(), none), cj(gj.cells(), none);
      // The example cell: the overlapping cell of i nearest the image centre.
      int best = -1;
      double best_d = 1e18;
      for (int c = 0; c < gi.cells(); ++c) {
        const auto cand = map.candidates(i, j, c);
        if (cand.empty()) continue;
        ci[c] = seen;
        for (int k : cand) cj[k] = seen;
        const double dx = (c % gi.cols + 0.5) * gi.cell_size - gi.width / 2.0;
        const double dy = (c / gi.cols + 0.5) * gi.cell_size - gi.height / 2.0;
        if (dx * dx + dy * dy < best_d) {
          best_d = dx * dx + dy * dy;
          best = c;
        }
      }
      if (best >= 0) {
        ci[best] = example;
        for (int k : map.candidates(i, j, best)) cj[k] = reach;
      }
      drawGrid(body, gi, 0, ci);
      drawGrid(body, gj, gi.width + gap, cj);
      char title[160];
      std::snprintf(title, sizeof(title),
                    "cam%d (left) into cam%d (right): %.0f%% of cam%d overlaps; red cell -> orange candidates", i, j,
                    100.0 * map.overlapFraction(i, j), i);
      cv::putText(canvas, title, cv::Point(8, 27), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
      const std::string path = dir + "/overlap_cam" + std::to_string(i) + "_cam" + std::to_string(j) + ".png";
      if (!cv::imwrite(path, canvas)) throw InputError(path + ": cannot write image");
      ++written;
    }
  }
  return written;
}

}  // namespace mcslam::rigtool
