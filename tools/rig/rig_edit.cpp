#include "rig_edit.hpp"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <random>

#include "mcslam/core/error.hpp"
#include "mcslam/core/json_writer.hpp"

namespace mcslam::rigtool {

namespace {
Vec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Vec3 v;
  do v = Vec3(n(rng), n(rng), n(rng));
  while (v.norm() < 1e-6);
  return v.normalized();
}
}  // namespace

Rig perturbExtrinsic(const Rig& rig, int camera, double translation_m, double rotation_deg, uint64_t seed) {
  if (camera < 0 || camera >= rig.size()) {
    throw InputError("--camera " + std::to_string(camera) + ": the rig has cameras 0.." +
                     std::to_string(rig.size() - 1));
  }
  std::mt19937_64 rng(seed);
  const Vec3 dt = translation_m * randomUnit(rng);
  const Vec3 axis = randomUnit(rng);
  Rig out = rig;
  SE3& T = out.cameras[camera].T_b_c;
  T.t += dt;
  T.R = so3Exp(axis * rotation_deg * M_PI / 180.0) * T.R;
  return out;
}

void printComparison(const Rig& a, const Rig& b, bool json) {
  if (a.size() != b.size()) {
    throw InputError("the calibrations have " + std::to_string(a.size()) + " and " + std::to_string(b.size()) +
                     " cameras");
  }
  JsonWriter j(std::cout);
  if (json)
    j.beginObject().key("cameras").beginArray();
  else
    std::printf("camera  translation (mm)  rotation (deg)   (poses relative to each calibration's camera 0)\n");
  for (int c = 0; c < a.size(); ++c) {
    const SE3 pa = a.T_b_c(0).inverse() * a.T_b_c(c);
    const SE3 pb = b.T_b_c(0).inverse() * b.T_b_c(c);
    const double dt = (pa.t - pb.t).norm();
    const double dr = rotationAngle(pa.R, pb.R) * 180.0 / M_PI;
    if (json)
      j.beginObject().key("index").value(c).key("translation_m").value(dt).key("rotation_deg").value(dr).endObject();
    else
      std::printf("  cam%-3d %12.2f  %14.4f\n", c, dt * 1e3, dr);
  }
  if (json) j.endArray().endObject();
}

}  // namespace mcslam::rigtool
