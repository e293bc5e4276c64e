// The image codec module (mcslam_image_codec.so): PNG, JPEG and every other format OpenCV's imgcodecs knows,
// decoded to 8-bit grey. It is a module of its own because imgcodecs maps ~110 shared libraries (GDAL, GDCM,
// poppler, ...; ~40 MB resident) that a daemon on cameras, or replaying PGM, never needs; mcslam_dataset loads
// it on first need (image_codec_loader.cpp). Only the two functions below are exported.
#include <cstdio>
#include <cstring>
#include <exception>
#include <opencv2/imgcodecs.hpp>

#include "image_codec_abi.h"

namespace {

int fail(char* error, size_t error_size, const char* reason) {
  if (error && error_size > 0) std::snprintf(error, error_size, "%s", reason);
  return 1;
}

}  // namespace

extern "C" __attribute__((visibility("default"))) int mcslam_image_codec_abi_version(void) {
  return MCSLAM_IMAGE_CODEC_ABI_VERSION;
}

extern "C" __attribute__((visibility("default"))) int mcslam_image_codec_read_grey(const char* path,
                                                                                   mcslam_grey_target_fn target,
                                                                                   void* context, char* error,
                                                                                   size_t error_size) {
  try {
    const cv::Mat grey = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (grey.empty())
      return fail(error, error_size, "cannot read image (missing, unreadable, or not a format OpenCV decodes)");
    ptrdiff_t stride = 0;
    uint8_t* out = target(context, grey.cols, grey.rows, &stride);
    if (!out) return fail(error, error_size, "no buffer for the decoded image");
    for (int y = 0; y < grey.rows; ++y)
      std::memcpy(out + y * stride, grey.ptr<uint8_t>(y), static_cast<size_t>(grey.cols));
    return 0;
  } catch (const std::exception& e) {
    return fail(error, error_size, e.what());
  }
}
