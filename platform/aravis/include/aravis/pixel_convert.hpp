#pragma once
// Camera pixel formats to 8-bit grey, into a preallocated image (no allocation).
#include <cstddef>
#include <cstdint>
#include <string>

#include "mcslam/core/image.hpp"

namespace mcslam::platform {

enum class PixelLayout { Mono8, BayerRG8, BayerGR8, BayerGB8, BayerBG8 };

// "Mono8", "BayerRG8", ... (GenICam names). Throws InputError for anything else.
PixelLayout pixelLayoutFromName(const std::string& name);
const char* pixelLayoutName(PixelLayout layout);

// Converts a tightly packed (stride = width) buffer of `size` bytes into `out`, which must already have
// the width and height. False when the buffer is too small or the sizes differ.
bool convertToGrey(PixelLayout layout, const uint8_t* data, std::size_t size, int width, int height, Image& out);

}  // namespace mcslam::platform
