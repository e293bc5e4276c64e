// The calibration readers (calib/calibration_io.hpp): a Kalibr camchain from memory, or an EuRoC sensor.yaml through
// a file. A Kalibr rig that was read must be written and read back (formatKalibrRig -> parseKalibrRig). Documented
// outcome for bad input: InputError.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz_support.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"

namespace {

// A rig the reader accepted and the writer wrote must read back: an error here is a finding.
void roundTrip(const mcslam::Rig& rig) {
  try {
    if (mcslam::parseKalibrRig(mcslam::formatKalibrRig(rig), "written.yaml").size() == rig.size()) return;
    std::fprintf(stderr, "the written rig reads back with another camera count\n");
  } catch (const mcslam::InputError& e) {
    std::fprintf(stderr, "the written rig does not read back: %s\n", e.what());
  }
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string text = mcslam::fuzz::text(data, size);
  try {
    // loadRigFromPath's rule: a top-level T_BS is an EuRoC sensor.yaml (read from a file only), else Kalibr.
    if (text.find("T_BS:") != std::string::npos)
      (void)mcslam::loadEurocSensorRig({mcslam::fuzz::tempFolder().write("sensor.yaml", text)});
    else
      roundTrip(mcslam::parseKalibrRig(text, "camchain.yaml"));
  } catch (const mcslam::InputError&) {
  }
  return 0;
}
