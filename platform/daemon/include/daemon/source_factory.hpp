#pragma once
// Creates the source named by source.type. Throws InputError (unreachable camera, missing dataset).
#include <memory>

#include "daemon/daemon_config.hpp"
#include "sources/frame_source.hpp"

namespace mcslam::platform {

std::unique_ptr<FrameSource> createSource(const DaemonConfig& config);

}  // namespace mcslam::platform
