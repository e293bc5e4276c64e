// The image file readers (dataset/image_file.hpp): our binary PGM reader, without and with a camera's size bound,
// and, for a PNG or JPEG, the size check of their headers before decoding (the codec module; the decoders
// themselves are OpenCV's). Documented outcome for bad input: InputError.
#include <cstdint>
#include <cstring>
#include <string>

#include "fuzz_support.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/image_file.hpp"

namespace {

bool isPngOrJpeg(const uint8_t* data, std::size_t size) {
  return (size >= 8 && std::memcmp(data, "\x89PNG\r\n\x1a\n", 8) == 0) ||
         (size >= 2 && data[0] == 0xff && data[1] == 0xd8);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  static mcslam::Image image;
  const std::string path = mcslam::fuzz::tempFolder().write("image", mcslam::fuzz::text(data, size));
  const mcslam::ImageBound camera{64, 48};
  try {
    mcslam::readPgmFile(path, image);
  } catch (const mcslam::InputError&) {
  }
  try {
    mcslam::readPgmFile(path, image, camera);
  } catch (const mcslam::InputError&) {
  }
  if (!isPngOrJpeg(data, size)) return 0;
  try {
    mcslam::readGreyImageFile(path, image, camera);
  } catch (const mcslam::InputError&) {
  }
  return 0;
}
