// mcslam-features: the front-end on one rig frame of a dataset — multi-view features (keypoints per camera
// and their 3D point in the body frame) and mono features.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/config_section.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/core/json_writer.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/pipeline/dataset_frame.hpp"
#include "mcslam/pipeline/front_end.hpp"

using namespace mcslam;

namespace {

void keypointJson(JsonWriter& j, int cam, const Keypoint& kp) {
  j.beginObject();
  j.key("camera").value(cam);
  j.key("x").value(static_cast<double>(kp.x));
  j.key("y").value(static_cast<double>(kp.y));
  j.key("octave").value(static_cast<int>(kp.octave));
  j.endObject();
}

void printJson(const FrameFeatures& f, std::size_t frame) {
  JsonWriter j(std::cout);
  j.beginObject();
  j.key("frame").value(static_cast<unsigned long long>(frame));
  j.key("timestamp_ns").value(static_cast<long long>(f.t));
  j.key("keypoints_per_camera").beginArray();
  for (int c = 0; c < f.cameras(); ++c) j.value(f.present[c] ? f.sets[c].count : 0);
  j.endArray();
  j.key("multiview").beginArray();
  for (int t = 0; t < f.mv_count; ++t) {
    const MultiViewFeature& mv = f.mv[t];
    j.beginObject();
    j.key("keypoints").beginArray();
    for (int r = 0; r < mv.size; ++r) {
      const KeypointRef& ref = f.mv_refs[mv.first + r];
      keypointJson(j, ref.cam, f.sets[ref.cam].keypoints[ref.index]);
    }
    j.endArray();
    j.key("has_point").value(mv.has_point);
    j.key("metric").value(mv.metric);
    j.key("point_body").vector(mv.p_b, 3);
    j.key("relative_depth_sigma").value(static_cast<double>(mv.relative_depth_sigma));
    j.endObject();
  }
  j.endArray();
  j.key("mono").beginArray();
  for (int c = 0; c < f.cameras(); ++c) {
    for (int k = 0; k < f.sets[c].count; ++k) {
      if (f.mv_of[c][k] < 0) keypointJson(j, c, f.sets[c].keypoints[k]);
    }
  }
  j.endArray();
  j.endObject();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mcslam-features: multi-view and mono features of one rig frame"};
  std::string dataset_dir, cameras_text, config_path;
  std::size_t frame = 0;
  bool json = false;
  app.add_option("DATASET", dataset_dir, "Dataset folder (ASL with camchain.yaml, EuRoC or KITTI)")->required();
  app.add_option("--frame", frame, "Rig frame index (0-based)")->capture_default_str();
  app.add_option("--cameras", cameras_text, "Cameras to use, by calibration index, e.g. 0,1,2");
  app.add_option("--config", config_path, "YAML with a slam: section (as mcslam-run --config); default: built-in");
  app.add_flag("--json", json, "Print JSON: multiview[keypoints[camera,x,y,octave], has_point, point_body], mono[...]");
  CLI11_PARSE(app, argc, argv);
  try {
    DatasetOptions dopt;
    if (!cameras_text.empty()) dopt.cameras = parseCameraList(cameras_text);
    const Dataset ds = Dataset::open(dataset_dir, dopt);
    if (frame >= ds.size()) {
      throw InputError(dataset_dir + ": --frame " + std::to_string(frame) + " is past the last frame (" +
                       std::to_string(ds.size()) + " frames)");
    }
    YAML::Node slam;
    if (!config_path.empty()) {
      const YAML::Node root = parseYamlText(readTextFile(config_path, kMaxConfigFileBytes), config_path);
      slam = root.IsMap() && root["slam"] ? root["slam"] : root;
    }
    const PipelineConfig config = parsePipelineConfig(slam, config_path.empty() ? "defaults" : config_path, ds.rig());
    FrontEnd front(ds.rig(), config);
    DatasetFrame images;
    images.load(ds, frame);
    if (!images.error().empty()) std::fprintf(stderr, "mcslam-features: %s\n", images.error().c_str());
    FrameFeatures features(ds.rig().size(), config.orb.max_features);
    front.compute(images.view(), features);
    if (json) {
      printJson(features, frame);
    } else {
      const MultiViewStats& s = front.multiViewStats();
      std::printf(
          "frame %zu: %d keypoints in %d cameras, %d multi-view features (%d with a point, %d metric), %d mono\n",
          frame, features.keypointCount(), ds.rig().size(), features.mv_count, s.tracks_with_point, s.metric_tracks,
          features.monoCount());
      // How well the points are known: what initialization and landmark creation select by.
      int within[4] = {0, 0, 0, 0};
      const double bounds[4] = {0.01, 0.03, 0.06, 0.15};
      for (int t = 0; t < features.mv_count; ++t) {
        for (int b = 0; b < 4; ++b)
          within[b] += features.mv[t].has_point && features.mv[t].relative_depth_sigma <= bounds[b];
      }
      std::printf("points by relative depth sigma: <=1%% %d, <=3%% %d, <=6%% %d, <=15%% %d\n", within[0], within[1],
                  within[2], within[3]);
      std::printf("two-view tracks dropped as ambiguous along the epipolar curve: %d\n", s.ambiguous);
      std::printf("front-end: extraction %.1f ms, multi-view %.1f ms\n", front.timing().extraction_ms,
                  front.timing().multiview_ms);
    }
  } catch (const InputError& e) {
    std::fprintf(stderr, "mcslam-features: %s\n", e.what());
    return 2;
  }
  return 0;
}
