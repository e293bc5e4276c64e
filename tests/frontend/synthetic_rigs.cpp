#include "synthetic_rigs.hpp"

#include <cmath>

#include "mcslam/calib/calibration_io.hpp"
#include "test_support.hpp"

namespace mcslam::test {

Rig ring8Rig(double hfov_deg) {
  Rig rig;
  const int w = 640, h = 480;
  const double f = (w / 2.0) / std::tan(hfov_deg * M_PI / 360.0);
  for (int i = 0; i < 8; ++i) {
    const double yaw = i * M_PI / 4.0;
    RigCamera c;
    c.name = "cam" + std::to_string(i);
    c.source_index = i;
    c.model = CameraModel(w, h, f, f, w / 2.0 - 0.5, h / 2.0 - 0.5, Distortion::RadTan, {-0.05, 0.01, 0.0, 0.0});
    // Camera z (optical axis) turned about the body y axis; y stays down.
    const Mat3 R = Eigen::AngleAxisd(yaw, Vec3::UnitY()).toRotationMatrix();
    c.T_b_c = SE3(R, R * Vec3(0, 0, 0.2));
    rig.cameras.push_back(c);
  }
  return rig;
}

Rig isecRig() { return loadKalibrRig(dataPath("calib/isec_5cam_camchain.yaml")); }

std::vector<ScenePoint> randomScene(const Rig& rig, int count, double min_depth, double max_depth, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> cam(0, rig.size() - 1);
  std::vector<ScenePoint> out;
  while (static_cast<int>(out.size()) < count) {
    // A random pixel of a random camera, pushed to a random depth.
    const int c = cam(rng);
    const CameraModel& m = rig.model(c);
    Vec3 b;
    if (!m.unproject(Vec2(u(rng) * (m.width() - 1), u(rng) * (m.height() - 1)), b)) continue;
    const double inv = 1.0 / min_depth + u(rng) * (1.0 / max_depth - 1.0 / min_depth);
    ScenePoint sp;
    sp.p_b = rig.T_b_c(c) * (b * (1.0 / inv) / b.z());
    sp.visible.assign(rig.size(), false);
    sp.uv.assign(rig.size(), Vec2::Zero());
    for (int k = 0; k < rig.size(); ++k) {
      Vec2 uv;
      if (rig.model(k).project(rig.T_b_c(k).inverse() * sp.p_b, uv) && rig.model(k).inImage(uv)) {
        sp.visible[k] = true;
        sp.uv[k] = uv;
      }
    }
    out.push_back(sp);
  }
  return out;
}

}  // namespace mcslam::test
