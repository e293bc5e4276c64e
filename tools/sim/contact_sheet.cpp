#include "contact_sheet.hpp"

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "mcslam/core/error.hpp"

namespace mcslam::sim {

namespace {
constexpr int kGap = 4;
constexpr uint8_t kBackground = 40;  // dark grey: tiles stand out, black sky/invalid corners stay visible

// Label with a dark outline so it reads on bright and dark images alike.
void drawLabel(cv::Mat& tile, const std::string& text) {
  const double size = std::clamp(tile.rows / 180.0, 0.4, 1.2);
  const int thick = std::max(1, static_cast<int>(size * 1.5));
  const cv::Point at(static_cast<int>(6 * size) + 2, static_cast<int>(22 * size) + 2);
  cv::putText(tile, text, at, cv::FONT_HERSHEY_SIMPLEX, size, cv::Scalar(0), thick + 2, cv::LINE_AA);
  cv::putText(tile, text, at, cv::FONT_HERSHEY_SIMPLEX, size, cv::Scalar(255), thick, cv::LINE_AA);
}
}  // namespace

void writeContactSheet(const std::string& path, const std::vector<SheetTile>& tiles, double scale, int columns) {
  if (tiles.empty()) throw InputError(path + ": no camera to show");
  // Cells as large as the largest scaled camera (rigs may mix resolutions).
  std::vector<cv::Mat> scaled;
  int cell_w = 0, cell_h = 0;
  for (const SheetTile& t : tiles) {
    const cv::Mat full(t.image->height(), t.image->width(), CV_8U, const_cast<uint8_t*>(t.image->data()));
    const cv::Size size(std::max(1, static_cast<int>(std::lround(full.cols * scale))),
                        std::max(1, static_cast<int>(std::lround(full.rows * scale))));
    cv::Mat small;
    cv::resize(full, small, size, 0, 0, cv::INTER_AREA);
    drawLabel(small, t.label);
    cell_w = std::max(cell_w, small.cols);
    cell_h = std::max(cell_h, small.rows);
    scaled.push_back(small);
  }
  const int n = static_cast<int>(scaled.size());
  const int cols = std::min(n, std::max(1, columns)), rows = (n + cols - 1) / cols;
  cv::Mat sheet(rows * cell_h + (rows + 1) * kGap, cols * cell_w + (cols + 1) * kGap, CV_8U, cv::Scalar(kBackground));
  for (int i = 0; i < n; ++i) {
    const int x = kGap + (i % cols) * (cell_w + kGap), y = kGap + (i / cols) * (cell_h + kGap);
    scaled[i].copyTo(sheet(cv::Rect(x, y, scaled[i].cols, scaled[i].rows)));
  }
  bool ok = false;
  try {
    ok = cv::imwrite(path, sheet, {cv::IMWRITE_PNG_COMPRESSION, 9});
  } catch (const cv::Exception& e) {
    throw InputError(path + ": cannot write the contact sheet (" + e.err + ")");
  }
  if (!ok) throw InputError(path + ": cannot write the contact sheet");
}

}  // namespace mcslam::sim
