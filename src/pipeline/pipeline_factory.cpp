// Temporary stand-in until the visual odometry lands: accepts an empty `slam:` section and
// returns a processor that reports every frame as not initialized.
#include "mcslam/pipeline/pipeline_factory.hpp"

#include "mcslam/core/error.hpp"

namespace mcslam {

namespace {
class NotYetProcessor final : public FrameProcessor {
 public:
  void process(const RigFrameView& frame, PoseEstimate& out) override {
    out = PoseEstimate{};
    out.t = frame.t;
    out.sequence = frame.sequence;
    out.state = TrackingState::NotInitialized;
  }
};
}  // namespace

void validatePipelineConfig(const YAML::Node& slam, const std::string& source, const Rig& rig) {
  if (slam && !slam.IsNull() && !slam.IsMap()) throw InputError(source + ": 'slam' must be a map");
  if (rig.size() < 1) throw InputError(source + ": the rig has no cameras");
}

std::string effectivePipelineConfig(const YAML::Node& slam, const std::string& source, const Rig& rig) {
  validatePipelineConfig(slam, source, rig);
  return "slam: {}\n";
}

std::unique_ptr<FrameProcessor> createPipeline(const YAML::Node& slam, const std::string& source, const Rig& rig) {
  validatePipelineConfig(slam, source, rig);
  return std::make_unique<NotYetProcessor>();
}

}  // namespace mcslam
