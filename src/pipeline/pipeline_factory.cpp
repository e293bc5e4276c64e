#include "mcslam/pipeline/pipeline_factory.hpp"

#include "mcslam/pipeline/slam_pipeline.hpp"

namespace mcslam {

void validatePipelineConfig(const YAML::Node& slam, const std::string& source, const Rig& rig) {
  parsePipelineConfig(slam, source, rig);
}

std::string effectivePipelineConfig(const YAML::Node& slam, const std::string& source, const Rig& rig) {
  return formatPipelineConfig(parsePipelineConfig(slam, source, rig));
}

std::unique_ptr<FrameProcessor> createPipeline(const YAML::Node& slam, const std::string& source, const Rig& rig,
                                               bool live) {
  PipelineConfig config = parsePipelineConfig(slam, source, rig);
  config.places.repeatable = !live;
  config.odometry.repeatable = !live;
  return std::make_unique<SlamPipeline>(rig, config);
}

}  // namespace mcslam
