// The image codec module (mcslam_image_codec.so): PNG, JPEG and every other format OpenCV's imgcodecs knows,
// decoded to 8-bit grey. It is a module of its own because imgcodecs maps ~110 shared libraries (GDAL, GDCM,
// poppler, ...; ~40 MB resident) that a daemon on cameras, or replaying PGM, never needs; mcslam_dataset loads
// it on first need (image_codec_loader.cpp). Only the two functions below are exported.
#include <algorithm>
#include <cstdint>
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

uint32_t bigEndian(const unsigned char* p, int bytes) {
  uint32_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

// The size a PNG says it has: the IHDR chunk right after the signature.
bool pngSize(std::FILE* f, int& width, int& height) {
  unsigned char h[24];
  static const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (std::fread(h, 1, sizeof h, f) != sizeof h || std::memcmp(h, signature, 8) != 0 ||
      std::memcmp(h + 12, "IHDR", 4) != 0)
    return false;
  width = static_cast<int>(std::min<uint32_t>(bigEndian(h + 16, 4), 1u << 30));
  height = static_cast<int>(std::min<uint32_t>(bigEndian(h + 20, 4), 1u << 30));
  return true;
}

// The size a JPEG says it has: its start-of-frame segment, found by walking the segments from the start.
bool jpegSize(std::FILE* f, int& width, int& height) {
  unsigned char h[9];
  if (std::fread(h, 1, 2, f) != 2 || h[0] != 0xff || h[1] != 0xd8) return false;
  for (int segments = 0; segments < 1000; ++segments) {
    if (std::fread(h, 1, 4, f) != 4 || h[0] != 0xff) return false;
    const int marker = h[1];
    const long length = static_cast<long>(bigEndian(h + 2, 2));
    const bool start_of_frame = marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
    if (start_of_frame) {
      if (std::fread(h, 1, 5, f) != 5) return false;
      height = static_cast<int>(bigEndian(h + 1, 2));
      width = static_cast<int>(bigEndian(h + 3, 2));
      return true;
    }
    if (length < 2 || std::fseek(f, length - 2, SEEK_CUR) != 0) return false;
  }
  return false;
}

// The size the file's header says, for the formats whose header is read here (PNG, JPEG); false otherwise.
bool headerSize(const char* path, int& width, int& height) {
  std::FILE* f = std::fopen(path, "rb");
  if (!f) return false;
  bool known = pngSize(f, width, height);
  if (!known) {
    std::rewind(f);
    known = jpegSize(f, width, height);
  }
  std::fclose(f);
  return known;
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
    // The buffer first when the header tells the size: a refusal then costs no decoding.
    int width = 0, height = 0;
    ptrdiff_t stride = 0;
    uint8_t* out = nullptr;
    if (headerSize(path, width, height)) {
      out = target(context, width, height, &stride);
      if (!out) return fail(error, error_size, "no buffer for an image of that size");
    }
    const cv::Mat grey = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (grey.empty())
      return fail(error, error_size, "cannot read image (missing, unreadable, or not a format OpenCV decodes)");
    if (out && (grey.cols != width || grey.rows != height))
      return fail(error, error_size, "the decoded image's size differs from its header's");
    if (!out) out = target(context, grey.cols, grey.rows, &stride);
    if (!out) return fail(error, error_size, "no buffer for the decoded image");
    for (int y = 0; y < grey.rows; ++y)
      std::memcpy(out + y * stride, grey.ptr<uint8_t>(y), static_cast<size_t>(grey.cols));
    return 0;
  } catch (const std::exception& e) {
    return fail(error, error_size, e.what());
  }
}
