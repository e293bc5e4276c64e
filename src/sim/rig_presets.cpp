#include "mcslam/sim/rig_presets.hpp"

#include <filesystem>

#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"

namespace mcslam::sim {

namespace {

// The five front cameras of the paper's rig, copied from tests/data/calib/isec_5cam_camchain.yaml so the
// presets work from any folder.
constexpr const char* kIsecCamchain = R"(cam0:
  camera_model: pinhole
  distortion_coeffs: [-0.21885064424496958, 0.2410536575038145, 0.00046415310494561044, 0.0009307765520526319]
  distortion_model: radtan
  intrinsics: [889.563290316852, 890.0746436168839, 372.5719632810755, 281.37647141718685]
  resolution: [720, 540]
cam1:
  T_cn_cnm1:
    - [0.9999319012012944, -0.010541223644698186, 0.0050075507024099205, -0.16477402502853067]
    - [0.0104596828830191, 0.9998166426941514, 0.01603982623914806, -0.0013347121665484654]
    - [-0.005175711927013185, -0.01598635655388188, 0.9998588142383806, 0.0010025236082949844]
    - [0.0, 0.0, 0.0, 1.0]
  camera_model: pinhole
  distortion_coeffs: [-0.21391880511879832, 0.24293509542886318, 0.000810015582157452, 0.0013318228828393473]
  distortion_model: radtan
  intrinsics: [891.5299601701228, 892.0352171803092, 381.58461763093493, 273.97341245103576]
  resolution: [720, 540]
cam2:
  T_cn_cnm1:
    - [0.9999671440990324, 0.007341153409633072, -0.0034377593056806608, -0.1655786426344912]
    - [-0.007337930124069653, 0.9999726264414879, 0.0009492887914181229, -0.001114356444954272]
    - [0.0034446340766229972, -0.000924031564111, 0.9999936403106519, 0.000310147327359811]
    - [0.0, 0.0, 0.0, 1.0]
  camera_model: pinhole
  distortion_coeffs: [-0.20118103039786672, 0.1271132082960252, 0.0025179473997906814, -6.975593672858932e-05]
  distortion_model: radtan
  intrinsics: [889.290678506305, 889.8621764706733, 375.8877766705681, 280.75320878077156]
  resolution: [720, 540]
cam3:
  T_cn_cnm1:
    - [0.9998873571089462, -0.003643634887046648, 0.014560117392918535, -0.16480420944054144]
    - [0.0032704587044315, 0.9996676293287203, 0.025572152278555735, -0.0006984065790356586]
    - [-0.014648453623105, -0.02552165349472741, 0.9995669402342925, 0.00234325317006322]
    - [0.0, 0.0, 0.0, 1.0]
  camera_model: pinhole
  distortion_coeffs: [-0.19363790937380654, 0.08165458623530929, 0.0013699481680648786, 0.00040654518905096864]
  distortion_model: radtan
  intrinsics: [889.5398463317027, 889.8606546679766, 366.4517335609714, 295.892880379859]
  resolution: [720, 540]
cam4:
  T_cn_cnm1:
    - [0.9998464165499777, 0.012600521364757021, -0.012180729596359307, -0.16638135994397243]
    - [-0.012881381222174, 0.9996464341974726, -0.02326105358925236, -0.0016771601633387388]
    - [0.0118833215042061, 0.02341438569788596, 0.9996552171686062, 0.0011157653517210814]
    - [0.0, 0.0, 0.0, 1.0]
  camera_model: pinhole
  distortion_coeffs: [-0.19695456100815334, 0.10777972484733667, 0.001315162911029086, 0.00048520892759210176]
  distortion_model: radtan
  intrinsics: [891.3663281750842, 891.806984193875, 383.78463614686814, 271.85215144562017]
  resolution: [720, 540]
)";

Rig isecFront() { return parseKalibrRig(kIsecCamchain, "isec preset"); }

Mat3 rotationAboutY(double angle) { return Eigen::AngleAxisd(angle, Vec3::UnitY()).toRotationMatrix(); }

Rig isecPreset() {
  Rig rig = isecFront();
  // Side cameras: centre camera's intrinsics, 6 cm either side of the centre camera and 8 cm behind it, looking
  // along -x (left) and +x (right) of cam0's frame: rotations of -+90 degrees about the vertical (y) axis.
  const RigCamera& centre = rig.cameras[2];
  const Vec3 mid = centre.T_b_c.t;
  RigCamera left = centre, right = centre;
  left.name = "cam5";
  left.source_index = 5;
  left.T_b_c = SE3(centre.T_b_c.R * rotationAboutY(-M_PI / 2), mid + centre.T_b_c.R * Vec3(-0.06, 0.0, -0.08));
  right.name = "cam6";
  right.source_index = 6;
  right.T_b_c = SE3(centre.T_b_c.R * rotationAboutY(M_PI / 2), mid + centre.T_b_c.R * Vec3(0.06, 0.0, -0.08));
  rig.cameras.push_back(left);
  rig.cameras.push_back(right);
  return rig;
}

Rig ring8Preset() {
  Rig rig;
  const CameraModel fisheye(720, 540, 260.0, 260.0, 359.5, 269.5, Distortion::Equidistant,
                            {0.012, -0.004, 0.0011, -0.00015});
  const double radius = 0.12;
  const Vec3 centre(0, 0, -radius);  // ring centre behind cam0, on its optical axis
  for (int k = 0; k < 8; ++k) {
    const double a = k * M_PI / 4;  // clockwise seen from above: cam2 looks right, cam6 left
    RigCamera c;
    c.name = "cam" + std::to_string(k);
    c.source_index = k;
    c.model = fisheye;
    c.T_b_c = SE3(rotationAboutY(a), centre + radius * Vec3(std::sin(a), 0, std::cos(a)));
    rig.cameras.push_back(c);
  }
  return rig;
}

}  // namespace

std::vector<std::string> rigPresetNames() { return {"isec", "stereo", "mono", "ring8"}; }

std::string describeRigPresets() {
  return "  isec    7 cameras: the paper's 5 front cameras (720x540 radtan, 0.165 m apart; cams 0-4) plus left (cam5)\n"
         "          and right (cam6) cameras at the middle of the rig\n"
         "  stereo  2 cameras of the isec rig (cams 0 and 1, baseline 0.165 m)\n"
         "  mono    1 camera (the isec centre camera)\n"
         "  ring8   8 equidistant fisheyes (720x540, ~160 deg) on a 0.12 m ring, 45 deg apart, neighbours overlap\n";
}

Rig makePresetRig(const std::string& name) {
  if (name == "isec") return isecPreset();
  if (name == "stereo") return isecFront().subset({0, 1});
  if (name == "mono") {
    Rig rig = isecFront().subset({2});
    rig.rebase(rig.cameras[0].T_b_c.inverse());
    rig.cameras[0].source_index = 0;
    return rig;
  }
  if (name == "ring8") return ring8Preset();
  std::string known;
  for (const std::string& n : rigPresetNames()) known += (known.empty() ? "" : ", ") + n;
  throw InputError("unknown rig preset '" + name + "' (presets: " + known + "; or give a Kalibr camchain file)");
}

Rig loadRig(const std::string& preset_or_path) {
  for (const std::string& n : rigPresetNames()) {
    if (preset_or_path == n) return makePresetRig(n);
  }
  std::error_code ec;
  if (!std::filesystem::exists(preset_or_path, ec)) {
    std::string known;
    for (const std::string& n : rigPresetNames()) known += (known.empty() ? "" : ", ") + n;
    throw InputError("rig '" + preset_or_path + "' is neither a preset (" + known + ") nor an existing camchain file");
  }
  return loadKalibrRig(preset_or_path);
}

SE3 rigMount(const Rig& rig) {
  // Platform axes in cam0's (body) frame: forward = cam0's z, left = -x, up = -y.
  Mat3 R_v_b;
  R_v_b << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const SE3& T_b_c0 = rig.T_b_c(0);
  const Mat3 R_v_b_aligned = R_v_b * T_b_c0.R.transpose();  // cam0's axes decide, whatever the body frame is
  Vec3 mean = Vec3::Zero();
  for (const RigCamera& c : rig.cameras) mean += c.T_b_c.t;
  mean /= std::max(1, rig.size());
  return SE3(R_v_b_aligned, -(R_v_b_aligned * mean));
}

}  // namespace mcslam::sim
