#pragma once
// mcslam-rig perturb / compare: what-if calibration errors, and how far two calibrations of one rig differ.
#include <cstdint>
#include <string>

#include "mcslam/calib/rig.hpp"

namespace mcslam::rigtool {

// Camera `camera`'s extrinsic moved by `translation_m` along a seeded random direction and turned by
// `rotation_deg` about a seeded random axis (body frame kept). Throws InputError for a bad camera index.
Rig perturbExtrinsic(const Rig& rig, int camera, double translation_m, double rotation_deg, uint64_t seed);

// Per camera: translation (m) and rotation (deg) between the two calibrations' camera poses relative to
// their own camera 0, so a different body frame does not count. Text or JSON on stdout.
void printComparison(const Rig& a, const Rig& b, bool json);

}  // namespace mcslam::rigtool
