#pragma once
// Internal: finds and loads the image codec module (image_codec_module.cpp) with dlopen, once per process.
#include <string>
#include <vector>

#include "image_codec_abi.h"

namespace mcslam::detail {

struct ImageCodecModule {
  mcslam_image_codec_read_fn read = nullptr;  // null when no candidate loaded
  std::string path;                           // the candidate that loaded
  std::string failure;                        // why none did: every path tried, with its reason
};

// Loads the first candidate that exists, loads and has our ABI version. Never unloaded.
ImageCodecModule loadImageCodecModule(const std::vector<std::string>& candidates);

// The process's module, loaded from imageCodecModuleCandidates() on the first call (thread-safe; a failure is
// remembered, not retried per image). Throws InputError naming `image` and the paths tried.
mcslam_image_codec_read_fn imageCodecReader(const std::string& image);

}  // namespace mcslam::detail
