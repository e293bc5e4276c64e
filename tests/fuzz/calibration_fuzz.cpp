// The calibration readers (calib/calibration_io.hpp, dataset/dataset.hpp): a Kalibr camchain from memory, and the
// same bytes as a file through loadRigFromPath (which reads EuRoC sensor.yaml files too). A rig that was read must
// be written and read back (formatKalibrRig -> parseKalibrRig). Documented outcome for bad input: InputError.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz_support.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"

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
    roundTrip(mcslam::parseKalibrRig(text, "camchain.yaml"));
  } catch (const mcslam::InputError&) {
  }
  try {
    (void)mcslam::loadRigFromPath(mcslam::fuzz::tempFolder().write("sensor.yaml", text));
  } catch (const mcslam::InputError&) {
  }
  return 0;
}
