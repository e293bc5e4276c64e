#pragma once
// Configuration of the SLAM pipeline: the `slam:` section of a config file (see config/slam.yaml for every
// key with its default). Parsed strictly: unknown keys, wrong types and out-of-range values are errors
// that name the file and the key.
#include <string>

#include <yaml-cpp/yaml.h>

#include "mcslam/calib/rig.hpp"
#include "mcslam/features/multiview_matcher.hpp"
#include "mcslam/features/orb_extractor.hpp"
#include "mcslam/features/overlap_map.hpp"
#include "mcslam/odometry/odometry_options.hpp"
#include "mcslam/places/places_options.hpp"

namespace mcslam {

// backend.refine_extrinsics: whether the back-end refines the extrinsics online.
enum class RefineExtrinsics {
  Auto,  // on when some camera overlaps no other (its calibration was chained), but not when no two cameras overlap
  On,
  Off,
};
// The name the configuration file gives it (auto, on, off).
const char* refineExtrinsicsName(RefineExtrinsics r);

struct PipelineConfig {
  OrbOptions orb;
  int feature_threads = 0;  // 0: one per core, at most one per camera
  OverlapOptions overlap;
  MultiViewOptions multiview;
  OdometryOptions odometry;
  RefineExtrinsics refine_extrinsics = RefineExtrinsics::Auto;
  PlacesOptions places;
};

// Defaults for `rig`, overridden by `slam` (may be null). Throws InputError naming `source` and the key.
PipelineConfig parsePipelineConfig(const YAML::Node& slam, const std::string& source, const Rig& rig);
// The configuration as the YAML `slam:` section that would produce it.
std::string formatPipelineConfig(const PipelineConfig& config);

}  // namespace mcslam
