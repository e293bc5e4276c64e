// mcslam-rig: inspect a rig calibration (cameras, poses in the body frame, baselines).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/core/json_writer.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "overlap_report.hpp"
#include "rig_edit.hpp"

using namespace mcslam;

namespace {

Vec3 viewingDirection(const RigCamera& c) { return c.T_b_c.R.col(2).normalized(); }

// Angle between the rays through the middle of the left and right image borders.
double horizontalFovDeg(const CameraModel& m) {
  Vec3 l, r;
  if (!m.unproject(Vec2(-0.5, m.cy()), l) || !m.unproject(Vec2(m.width() - 0.5, m.cy()), r)) return 0.0;
  return std::acos(std::clamp(l.dot(r), -1.0, 1.0)) * 180.0 / M_PI;
}

void printInfoJson(const Rig& rig) {
  JsonWriter j(std::cout);
  j.beginObject();
  j.key("cameras").beginArray();
  for (int i = 0; i < rig.size(); ++i) {
    const RigCamera& c = rig.cameras[i];
    const CameraModel& m = c.model;
    j.beginObject();
    j.key("index").value(i);
    j.key("name").value(c.name);
    j.key("model").value("pinhole");
    j.key("distortion").value(distortionName(m.distortion()));
    j.key("resolution").beginArray().value(m.width()).value(m.height()).endArray();
    j.key("intrinsics").beginArray().value(m.fx()).value(m.fy()).value(m.cx()).value(m.cy()).endArray();
    j.key("distortion_coeffs").vector(m.coeffs(), 4);
    j.key("position").vector(c.T_b_c.t, 3);
    j.key("direction").vector(viewingDirection(c), 3);
    j.key("horizontal_fov_deg").value(horizontalFovDeg(m));
    j.endObject();
  }
  j.endArray();
  j.key("baselines").beginArray();
  for (int a = 0; a < rig.size(); ++a) {
    j.beginArray();
    for (int b = 0; b < rig.size(); ++b) j.value((rig.T_b_c(a).t - rig.T_b_c(b).t).norm());
    j.endArray();
  }
  j.endArray();
  j.endObject();
}

void printInfoText(const Rig& rig, const std::string& path) {
  std::printf("%s: %d camera%s (body frame = cam0 unless configured)\n", path.c_str(), rig.size(),
              rig.size() == 1 ? "" : "s");
  for (int i = 0; i < rig.size(); ++i) {
    const RigCamera& c = rig.cameras[i];
    const CameraModel& m = c.model;
    const Vec3 p = c.T_b_c.t, d = viewingDirection(c);
    std::printf("  cam%d  pinhole/%-11s %4dx%-4d  f=(%.1f, %.1f) c=(%.1f, %.1f)  hfov %.1f deg\n", i,
                distortionName(m.distortion()), m.width(), m.height(), m.fx(), m.fy(), m.cx(), m.cy(),
                horizontalFovDeg(m));
    std::printf("        position [%+.4f %+.4f %+.4f] m   looks along [%+.3f %+.3f %+.3f]\n", p.x() + 0.0, p.y() + 0.0,
                p.z() + 0.0, d.x() + 0.0, d.y() + 0.0, d.z() + 0.0);
  }
  if (rig.size() > 1) {
    std::printf("baselines (m):\n      ");
    for (int b = 0; b < rig.size(); ++b) std::printf("  cam%-4d", b);
    std::printf("\n");
    for (int a = 0; a < rig.size(); ++a) {
      std::printf("  cam%d", a);
      for (int b = 0; b < rig.size(); ++b) std::printf("  %7.4f", (rig.T_b_c(a).t - rig.T_b_c(b).t).norm());
      std::printf("\n");
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mcslam-rig: inspect a multi-camera rig calibration"};
  app.require_subcommand(1);
  std::string calib;
  bool json = false;
  auto* info = app.add_subcommand("info", "Cameras, models, resolutions, poses in the body frame and baselines");
  info->add_option("CALIB", calib,
                   "Kalibr camchain/imu-camchain YAML, EuRoC sensor.yaml, KITTI calib.txt or a dataset folder")
      ->required();
  info->add_flag("--json", json,
                 "Print JSON (keys: cameras[index, model, distortion, resolution, position, direction], baselines)");

  OverlapOptions overlap;
  std::string png_dir;
  auto* ov =
      app.add_subcommand("overlap", "Overlap between camera pairs (paper eq. 1-2, full camera models, a depth range)");
  ov->add_option("CALIB", calib, "Calibration (as for info)")->required();
  ov->add_flag("--json", json, "Print JSON (keys: pairs[cameras, fraction], fraction_matrix)");
  ov->add_option("--png", png_dir, "Write one picture of the cells per overlapping camera pair into this folder");
  ov->add_option("--min-depth", overlap.min_depth, "Nearest scene depth, metres")->capture_default_str();
  ov->add_option("--max-depth", overlap.max_depth, "Farthest scene depth, metres")->capture_default_str();
  ov->add_option("--cell-size", overlap.cell_size_px, "Grid cell size, pixels")->capture_default_str();

  int camera = 0;
  double translation = 0.02, rotation_deg = 1.0;
  uint64_t seed = 1;
  std::string out_path, other;
  auto* perturb =
      app.add_subcommand("perturb", "Move one camera's extrinsic (what-if calibration error); writes Kalibr YAML");
  perturb->add_option("CALIB", calib, "Calibration (as for info)")->required();
  perturb->add_option("--camera", camera, "Camera index")->required();
  perturb->add_option("--translation", translation, "Translation error, metres (random direction)")
      ->capture_default_str();
  perturb->add_option("--rotation-deg", rotation_deg, "Rotation error, degrees (random axis)")->capture_default_str();
  perturb->add_option("--seed", seed, "Seed of the direction and axis")->capture_default_str();
  perturb->add_option("--out", out_path, "Kalibr camchain YAML to write")->required();
  auto* compare = app.add_subcommand("compare", "Per-camera extrinsic difference between two calibrations of one rig");
  compare->add_option("CALIB", calib, "First calibration")->required();
  compare->add_option("OTHER", other, "Second calibration (e.g. mcslam-run --extrinsics output)")->required();
  compare->add_flag("--json", json, "Print JSON (keys: cameras[index, translation_m, rotation_deg])");
  std::string subset;
  compare->add_option("--cameras", subset,
                      "Compare only these cameras of CALIB (e.g. 0,1,2,3,4: OTHER holds that subset)");
  CLI11_PARSE(app, argc, argv);
  try {
    const Rig rig = loadRigFromPath(calib);
    if (perturb->parsed()) {
      writeKalibrRig(rigtool::perturbExtrinsic(rig, camera, translation, rotation_deg, seed), out_path);
    } else if (compare->parsed()) {
      rigtool::printComparison(subset.empty() ? rig : rig.subset(parseCameraList(subset)), loadRigFromPath(other),
                               json);
    } else if (info->parsed()) {
      if (json)
        printInfoJson(rig);
      else
        printInfoText(rig, calib);
    } else {
      const OverlapMap map(rig, overlap);
      if (json)
        rigtool::printOverlapJson(rig, map);
      else
        rigtool::printOverlapText(rig, map);
      if (!png_dir.empty()) {
        const int n = rigtool::writeOverlapPngs(rig, map, png_dir);
        std::fprintf(stderr, "mcslam-rig: wrote %d picture%s to %s\n", n, n == 1 ? "" : "s", png_dir.c_str());
      }
    }
  } catch (const InputError& e) {
    std::fprintf(stderr, "mcslam-rig: %s\n", e.what());
    return 2;
  }
  return 0;
}
