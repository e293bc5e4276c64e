// The pipeline's `slam:` section (pipeline/pipeline_config.hpp): parseYamlText, parsePipelineConfig for a stereo
// rig, and the effective configuration it prints (formatPipelineConfig, what `--check-config` shows), which must read
// back as the same configuration. Documented outcome for bad input: InputError.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz_support.hpp"
#include "mcslam/core/config_section.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/pipeline/pipeline_config.hpp"

namespace {

mcslam::Rig stereoRig() {
  mcslam::Rig rig;
  for (int i = 0; i < 2; ++i) {
    mcslam::RigCamera c;
    c.name = "cam" + std::to_string(i);
    c.source_index = i;
    c.model = mcslam::CameraModel(640, 480, 400, 400, 320, 240, mcslam::Distortion::None);
    c.T_b_c.t = mcslam::Vec3(0.1 * i, 0, 0);
    rig.cameras.push_back(c);
  }
  return rig;
}

// The printed configuration of an accepted one must read back and print the same: an error is a finding.
void roundTrip(const std::string& printed, const mcslam::Rig& rig) {
  try {
    const YAML::Node again = mcslam::parseYamlText(printed, "effective.yaml");
    if (mcslam::formatPipelineConfig(mcslam::parsePipelineConfig(again["slam"], "effective.yaml", rig)) == printed)
      return;
    std::fprintf(stderr, "the effective configuration reads back differently:\n%s", printed.c_str());
  } catch (const mcslam::InputError& e) {
    std::fprintf(stderr, "the effective configuration does not read back: %s\n%s", e.what(), printed.c_str());
  }
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  static const mcslam::Rig rig = stereoRig();
  try {
    const YAML::Node root = mcslam::parseYamlText(mcslam::fuzz::text(data, size), "fuzz.yaml");
    const YAML::Node slam = root.IsMap() && root["slam"] ? root["slam"] : root;
    roundTrip(mcslam::formatPipelineConfig(mcslam::parsePipelineConfig(slam, "fuzz.yaml", rig)), rig);
  } catch (const mcslam::InputError&) {
  }
  return 0;
}
