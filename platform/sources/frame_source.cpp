#include "sources/frame_source.hpp"

#include <cstdio>

namespace mcslam::platform {

void FrameSource::health(char* out, std::size_t size) const { std::snprintf(out, size, "ok"); }

}  // namespace mcslam::platform
