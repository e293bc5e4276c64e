// The daemon's configuration reader (platform/daemon/daemon_config.hpp): parseDaemonConfig on the text, as if it were
// a file in an empty folder (relative paths lead nowhere; the simulated rig's presets resolve without files), then
// the effective configuration `--check-config` prints. Documented outcome for bad input: InputError.
#include <cstdint>
#include <string>

#include "daemon/daemon_config.hpp"
#include "fuzz_support.hpp"
#include "mcslam/core/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  static const std::string file = mcslam::fuzz::tempFolder().dir() + "/mcslamd.yaml";
  try {
    const mcslam::platform::DaemonConfig config =
        mcslam::platform::parseDaemonConfig(mcslam::fuzz::text(data, size), file);
    (void)mcslam::platform::effectiveDaemonConfig(config);
  } catch (const mcslam::InputError&) {
  }
  return 0;
}
