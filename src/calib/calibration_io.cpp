#include "mcslam/calib/calibration_io.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "mcslam/core/config_section.hpp"
#include "mcslam/core/error.hpp"

namespace mcslam {

namespace {

// Where a field lives, for error messages: "file.yaml: cam2: field 'intrinsics'".
struct Where {
  const std::string& source;
  const std::string& camera;
  std::string prefix() const { return source + ": " + camera + ": "; }
  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw InputError(prefix() + "field '" + field + "' " + what);
  }
};

std::string describe(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a map";
  return "nothing";
}

double toNumber(const YAML::Node& n, const Where& w, const std::string& field, std::size_t index) {
  double v = 0;
  if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v)) {
    w.fail(field, "entry " + std::to_string(index) + " is not a finite number: " + describe(n));
  }
  return v;
}

std::vector<double> readNumbers(const YAML::Node& cam, const Where& w, const std::string& field, std::size_t count) {
  const YAML::Node n = cam[field];
  if (!n) w.fail(field, "is missing");
  if (!n.IsSequence()) w.fail(field, "must be a list of " + std::to_string(count) + " numbers, got " + describe(n));
  if (n.size() != count) {
    w.fail(field, "must have " + std::to_string(count) + " numbers, got " + std::to_string(n.size()));
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < n.size(); ++i) out.push_back(toNumber(n[i], w, field, i));
  return out;
}

std::string readString(const YAML::Node& cam, const Where& w, const std::string& field) {
  const YAML::Node n = cam[field];
  if (!n) w.fail(field, "is missing");
  if (!n.IsScalar()) w.fail(field, "must be a word, got " + describe(n));
  return n.Scalar();
}

// Checks that a 4x4 matrix is a rigid transform and returns it re-orthonormalised.
SE3 toRigid(const Mat4& T, const Where& w, const std::string& field) {
  const Mat3 R = T.topLeftCorner<3, 3>();
  const double ortho = (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (ortho > 1e-4 || R.determinant() < 0.0) {
    std::ostringstream os;
    os << "is not a rigid transform: its rotation part is not a rotation (|R^T R - I| = " << ortho
       << ", det = " << R.determinant() << ")";
    w.fail(field, os.str());
  }
  const Vec4 last = T.row(3).transpose();
  if ((last - Vec4(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9) {
    w.fail(field, "is not a rigid transform: its last row must be [0, 0, 0, 1]");
  }
  SE3 out(R, T.topRightCorner<3, 1>());
  out.normalize();
  return out;
}

// Kalibr writes 4 rows of 4 numbers; OpenCV/EuRoC write {rows: 4, cols: 4, data: [16 numbers]}.
SE3 readTransform(const YAML::Node& cam, const Where& w, const std::string& field) {
  const YAML::Node n = cam[field];
  if (!n) w.fail(field, "is missing");
  Mat4 T;
  if (n.IsSequence()) {
    if (n.size() != 4) w.fail(field, "must have 4 rows of 4 numbers, got " + std::to_string(n.size()) + " rows");
    for (std::size_t r = 0; r < 4; ++r) {
      if (!n[r].IsSequence() || n[r].size() != 4) {
        w.fail(field, "row " + std::to_string(r) + " must have 4 numbers, got " + describe(n[r]));
      }
      for (std::size_t c = 0; c < 4; ++c) T(r, c) = toNumber(n[r][c], w, field, r * 4 + c);
    }
  } else if (n.IsMap()) {
    const YAML::Node data = n["data"];
    if (!data || !data.IsSequence() || data.size() != 16) {
      w.fail(field, "must have 'data' with 16 numbers (a 4x4 matrix, row by row)");
    }
    for (std::size_t i = 0; i < 16; ++i) T(i / 4, i % 4) = toNumber(data[i], w, field, i);
  } else {
    w.fail(field, "must be a 4x4 matrix, got " + describe(n));
  }
  return toRigid(T, w, field);
}

Distortion parseDistortion(const std::string& name, const Where& w, const std::string& field) {
  if (name == "radtan" || name == "radial-tangential" || name == "plumb_bob") return Distortion::RadTan;
  if (name == "equidistant" || name == "equi" || name == "fisheye") return Distortion::Equidistant;
  if (name == "none") return Distortion::None;
  w.fail(field, "has unknown value '" + name + "' (supported: radtan, equidistant, none)");
}

CameraModel readCameraModel(const YAML::Node& cam, const Where& w, const std::string& coeffs_field) {
  const std::string model = readString(cam, w, "camera_model");
  if (model != "pinhole") w.fail("camera_model", "has unsupported value '" + model + "' (supported: pinhole)");
  const std::vector<double> in = readNumbers(cam, w, "intrinsics", 4);
  if (!(in[0] > 0 && in[1] > 0)) w.fail("intrinsics", "must have positive focal lengths fx, fy");
  const std::vector<double> res = readNumbers(cam, w, "resolution", 2);
  for (double v : res) {
    if (!(v >= 1 && v <= 100000 && v == std::floor(v))) {
      w.fail("resolution", "must be two positive whole numbers [width, height]");
    }
  }
  Distortion dist = Distortion::None;
  std::array<double, 4> k{0, 0, 0, 0};
  if (cam["distortion_model"]) {
    dist = parseDistortion(readString(cam, w, "distortion_model"), w, "distortion_model");
    if (dist != Distortion::None || cam[coeffs_field]) {
      const std::vector<double> c = readNumbers(cam, w, coeffs_field, 4);
      std::copy(c.begin(), c.end(), k.begin());
    }
  } else if (cam[coeffs_field]) {
    // Coefficients without a model would be dropped: the lens would be taken for a distortion-free one.
    const std::vector<double> c = readNumbers(cam, w, coeffs_field, 4);
    if (std::any_of(c.begin(), c.end(), [](double v) { return v != 0; }))
      w.fail(coeffs_field, "is given without distortion_model (radtan or equidistant): say which model they are for");
  }
  return CameraModel(static_cast<int>(res[0]), static_cast<int>(res[1]), in[0], in[1], in[2], in[3], dist, k);
}

std::string stripOpenCvHeader(const std::string& text) {
  // yaml-cpp rejects OpenCV's "%YAML:1.0" directive; drop that line (and its comment).
  if (text.rfind("%YAML:", 0) == 0) {
    const auto eol = text.find('\n');
    return eol == std::string::npos ? std::string() : text.substr(eol + 1);
  }
  return text;
}

YAML::Node parseYaml(const std::string& text, const std::string& source) {
  return parseYamlText(stripOpenCvHeader(text), source);
}

// N of a key "camN"; -1 for a key that names no camera. InputError for N beyond the cameras a rig may have, or
// written with leading zeros (cam01 would be camera 1 beside cam1).
int cameraIndex(const std::string& key, const std::string& source) {
  if (key.size() <= 3 || key.compare(0, 3, "cam") != 0 ||
      !std::all_of(key.begin() + 3, key.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return -1;
  int index = -1;
  const auto [end, ec] = std::from_chars(key.data() + 3, key.data() + key.size(), index);
  if (ec != std::errc() || index >= kMaxRigCameras)
    throw InputError(source + ": " + key + ": a rig has at most " + std::to_string(kMaxRigCameras) +
                     " cameras (cam0 to cam" + std::to_string(kMaxRigCameras - 1) + ")");
  if (key != "cam" + std::to_string(index))
    throw InputError(source + ": " + key + ": camera keys are written without leading zeros (cam" +
                     std::to_string(index) + ")");
  return index;
}

void applyBody(Rig& rig, const RigLoadOptions& options) {
  if (options.T_body_cam0) rig.rebase(*options.T_body_cam0);
}

}  // namespace

std::string readTextFile(const std::string& path, std::size_t max_bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open file");
  std::string text;
  char chunk[65536];
  while (in.read(chunk, sizeof(chunk)) || in.gcount() > 0) {
    text.append(chunk, static_cast<std::size_t>(in.gcount()));
    if (text.size() > max_bytes)
      throw InputError(path + ": larger than " + std::to_string(max_bytes >> 20) + " MB, more than a file of this " +
                       "kind holds (is it the right file?)");
  }
  if (in.bad()) throw InputError(path + ": read error");
  return text;
}

Rig loadKalibrRig(const std::string& path, const RigLoadOptions& options) {
  return parseKalibrRig(readTextFile(path, kMaxConfigFileBytes), path, options);
}

Rig parseKalibrRig(const std::string& yaml_text, const std::string& source, const RigLoadOptions& options) {
  const YAML::Node root = parseYaml(yaml_text, source);
  if (!root.IsMap())
    throw InputError(source + ": expected a Kalibr camchain (keys cam0, cam1, ...), got " + describe(root));

  std::map<int, YAML::Node> cams;
  for (const auto& kv : root) {
    const int index = cameraIndex(kv.first.as<std::string>(), source);
    if (index >= 0) cams[index] = kv.second;
  }
  if (cams.empty()) throw InputError(source + ": no cameras found (expected keys cam0, cam1, ...)");
  int expected = 0;
  for (const auto& [index, node] : cams) {
    if (index != expected) {
      throw InputError(source + ": cam" + std::to_string(expected) +
                       " is missing (cameras must be numbered cam0, cam1, ... without gaps)");
    }
    ++expected;
  }

  Rig rig;
  std::vector<SE3> T_c_c0(cams.size());
  std::vector<std::optional<SE3>> T_c_imu(cams.size());
  for (const auto& [index, node] : cams) {
    const std::string name = "cam" + std::to_string(index);
    const Where w{source, name};
    if (!node.IsMap()) throw InputError(w.prefix() + "expected a map of fields, got " + describe(node));
    RigCamera rc;
    rc.name = name;
    rc.source_index = index;
    rc.model = readCameraModel(node, w, "distortion_coeffs");
    if (node["T_cam_imu"])
      T_c_imu[index] = readTransform(node, w, "T_cam_imu");
    else if (node["T_imu_cam"])
      T_c_imu[index] = readTransform(node, w, "T_imu_cam").inverse();

    if (index == 0) {
      T_c_c0[0] = SE3();
    } else if (node["T_cn_cnm1"]) {
      T_c_c0[index] = readTransform(node, w, "T_cn_cnm1") * T_c_c0[index - 1];
    } else if (T_c_imu[index] && T_c_imu[0]) {
      T_c_c0[index] = *T_c_imu[index] * T_c_imu[0]->inverse();
    } else {
      w.fail("T_cn_cnm1", "is missing (and no T_cam_imu on both this camera and cam0 to chain through the IMU)");
    }
    rc.T_b_c = T_c_c0[index].inverse();
    rig.cameras.push_back(rc);
  }
  if (T_c_imu[0]) rig.T_b_imu = *T_c_imu[0];  // body = cam0 here
  applyBody(rig, options);
  return rig;
}

Rig loadEurocSensorRig(const std::vector<std::string>& paths, const RigLoadOptions& options) {
  if (paths.empty()) throw InputError("EuRoC rig: no sensor.yaml files given");
  if (paths.size() > static_cast<std::size_t>(kMaxRigCameras))
    throw InputError(paths[kMaxRigCameras] + ": a rig has at most " + std::to_string(kMaxRigCameras) + " cameras");
  Rig rig;
  std::vector<SE3> T_B_c;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const std::string name = "cam" + std::to_string(i);
    const Where w{paths[i], name};
    const YAML::Node root = parseYaml(readTextFile(paths[i], kMaxConfigFileBytes), paths[i]);
    if (!root.IsMap()) throw InputError(paths[i] + ": expected an EuRoC sensor.yaml map");
    RigCamera rc;
    rc.name = name;
    rc.source_index = static_cast<int>(i);
    rc.model =
        readCameraModel(root, w, root["distortion_coefficients"] ? "distortion_coefficients" : "distortion_coeffs");
    T_B_c.push_back(readTransform(root, w, "T_BS"));
    rig.cameras.push_back(rc);
  }
  const SE3 T_c0_B = T_B_c[0].inverse();
  for (std::size_t i = 0; i < paths.size(); ++i) rig.cameras[i].T_b_c = T_c0_B * T_B_c[i];
  rig.T_b_imu = T_c0_B;
  applyBody(rig, options);
  return rig;
}

std::string formatKalibrRig(const Rig& rig) {
  std::ostringstream os;
  os.precision(17);
  auto matrix = [&os](const char* key, const SE3& T) {
    const Mat4 M = T.matrix();
    os << "  " << key << ":\n";
    for (int r = 0; r < 4; ++r) {
      os << "    - [";
      for (int c = 0; c < 4; ++c) os << (c ? ", " : "") << M(r, c);
      os << "]\n";
    }
  };
  for (int i = 0; i < rig.size(); ++i) {
    const RigCamera& c = rig.cameras[i];
    os << "cam" << i << ":\n";
    if (i > 0) matrix("T_cn_cnm1", c.T_b_c.inverse() * rig.cameras[i - 1].T_b_c);
    if (rig.T_b_imu) matrix("T_cam_imu", c.T_b_c.inverse() * *rig.T_b_imu);
    const CameraModel& m = c.model;
    os << "  camera_model: pinhole\n";
    os << "  intrinsics: [" << m.fx() << ", " << m.fy() << ", " << m.cx() << ", " << m.cy() << "]\n";
    os << "  distortion_model: " << distortionName(m.distortion()) << "\n";
    os << "  distortion_coeffs: [" << m.coeffs()[0] << ", " << m.coeffs()[1] << ", " << m.coeffs()[2] << ", "
       << m.coeffs()[3] << "]\n";
    os << "  resolution: [" << m.width() << ", " << m.height() << "]\n";
  }
  return os.str();
}

void writeKalibrRig(const Rig& rig, const std::string& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw InputError(path + ": cannot write file");
  out << formatKalibrRig(rig);
  out.flush();  // a full disk shows only when the buffer goes out
  if (!out) throw InputError(path + ": write failed");
}

Rig Rig::subset(const std::vector<int>& indices) const {
  if (indices.empty()) throw InputError("camera selection is empty");
  Rig out;
  out.T_b_imu = T_b_imu;
  std::vector<bool> used(cameras.size(), false);
  for (int i : indices) {
    if (i < 0 || i >= size()) {
      throw InputError("camera " + std::to_string(i) + " does not exist (the rig has cameras 0.." +
                       std::to_string(size() - 1) + ")");
    }
    if (used[i]) throw InputError("camera " + std::to_string(i) + " is selected twice");
    used[i] = true;
    out.cameras.push_back(cameras[i]);
  }
  return out;
}

void Rig::rebase(const SE3& T_newb_oldb) {
  for (RigCamera& c : cameras) c.T_b_c = T_newb_oldb * c.T_b_c;
  if (T_b_imu) T_b_imu = T_newb_oldb * *T_b_imu;
}

std::vector<int> parseCameraList(const std::string& text) {
  std::vector<int> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      const int v = std::stoi(item, &used);
      if (used != item.size() || v < 0) throw std::invalid_argument("x");
      out.push_back(v);
    } catch (const std::exception&) {
      throw InputError("camera list '" + text + "': '" + item + "' is not a camera index (expected e.g. 0,2,4)");
    }
  }
  if (out.empty()) throw InputError("camera list '" + text + "' is empty (expected e.g. 0,2,4)");
  return out;
}

}  // namespace mcslam
