#pragma once
// Creating the SLAM pipeline from the `slam:` section of a configuration.
//
// The section is validated strictly (unknown key, wrong type, zero capacity -> InputError naming the
// key and the file); an absent or empty section means defaults. Memory for every capacity is
// allocated here, before the first frame.
#include <memory>
#include <string>

#include <yaml-cpp/yaml.h>

#include "mcslam/calib/rig.hpp"
#include "mcslam/pipeline/frame_processor.hpp"

namespace mcslam {

// Throws InputError when the section is invalid. `source` names the file in messages.
void validatePipelineConfig(const YAML::Node& slam_section, const std::string& source, const Rig& rig);

// The effective configuration (defaults filled in) as YAML text, for --check-config.
std::string effectivePipelineConfig(const YAML::Node& slam_section, const std::string& source, const Rig& rig);

// `live`: a rig's frames as they come (mcslamd), where no frame waits for background work (a loop's correction
// lands at the first frame it is ready, a scale estimate at the first settled keyframe), instead of a run that
// repeats exactly.
std::unique_ptr<FrameProcessor> createPipeline(const YAML::Node& slam_section, const std::string& source,
                                               const Rig& rig, bool live = false);

}  // namespace mcslam
