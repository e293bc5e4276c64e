#include "aravis/pixel_convert.hpp"

#include <cstring>

#include <opencv2/imgproc.hpp>

#include "mcslam/core/error.hpp"

namespace mcslam::platform {

PixelLayout pixelLayoutFromName(const std::string& n) {
  if (n == "Mono8") return PixelLayout::Mono8;
  if (n == "BayerRG8") return PixelLayout::BayerRG8;
  if (n == "BayerGR8") return PixelLayout::BayerGR8;
  if (n == "BayerGB8") return PixelLayout::BayerGB8;
  if (n == "BayerBG8") return PixelLayout::BayerBG8;
  throw InputError("pixel_format: '" + n + "' is not Mono8, BayerRG8, BayerGR8, BayerGB8 or BayerBG8");
}

const char* pixelLayoutName(PixelLayout l) {
  switch (l) {
    case PixelLayout::Mono8: return "Mono8";
    case PixelLayout::BayerRG8: return "BayerRG8";
    case PixelLayout::BayerGR8: return "BayerGR8";
    case PixelLayout::BayerGB8: return "BayerGB8";
    case PixelLayout::BayerBG8: return "BayerBG8";
  }
  return "?";
}

bool convertToGrey(PixelLayout layout, const uint8_t* data, std::size_t size, int width, int height, Image& out) {
  if (out.width() != width || out.height() != height) return false;
  if (size < static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) return false;
  if (layout == PixelLayout::Mono8) {
    std::memcpy(out.data(), data, static_cast<std::size_t>(width) * height);
    return true;
  }
  // OpenCV names a Bayer pattern after the second row's second and third pixels, GenICam after the
  // top-left 2x2 cell: GenICam RG is OpenCV BG, and so on (checked by a test with a known colour).
  int code = cv::COLOR_BayerBG2GRAY;
  switch (layout) {
    case PixelLayout::BayerRG8: code = cv::COLOR_BayerBG2GRAY; break;
    case PixelLayout::BayerGR8: code = cv::COLOR_BayerGB2GRAY; break;
    case PixelLayout::BayerGB8: code = cv::COLOR_BayerGR2GRAY; break;
    case PixelLayout::BayerBG8: code = cv::COLOR_BayerRG2GRAY; break;
    case PixelLayout::Mono8: break;
  }
  const cv::Mat src(height, width, CV_8UC1, const_cast<uint8_t*>(data));
  cv::Mat dst(height, width, CV_8UC1, out.data());  // wraps our buffer: cvtColor writes in place
  cv::cvtColor(src, dst, code);
  return dst.data == out.data();
}

}  // namespace mcslam::platform
