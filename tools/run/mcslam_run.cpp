// mcslam-run: runs the SLAM pipeline on a recorded dataset as fast as it can, and writes the trajectory of
// every frame, the keyframes, per-stage timing and tracking statistics.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>
#include <chrono>
#include <cstdio>
#include <future>
#include <iostream>

#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/pipeline/dataset_frame.hpp"
#include "mcslam/pipeline/slam_pipeline.hpp"
#include "run_report.hpp"

using namespace mcslam;

namespace {

// The `slam:` section of a config file; a file holding only the section's keys is accepted too.
YAML::Node slamSection(const std::string& path) {
  if (path.empty()) return YAML::Node();
  YAML::Node root;
  try {
    root = YAML::Load(readTextFile(path));
  } catch (const YAML::Exception& e) {
    throw InputError(path + ": not valid YAML at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (root.IsMap() && root["slam"]) return root["slam"];
  return root;
}

DatasetFrame loadFrame(const Dataset& ds, std::size_t i) {
  DatasetFrame f;
  f.load(ds, i);
  return f;
}

// Frame i through the front-end: features computed into `out`.
struct PreparedFrame {
  PipelineTiming timing;  // features_ms
  double wall_ms = 0;     // front-end, as SlamPipeline::process counts it (decoding not included)
  std::string error;      // an unreadable image (its camera is then absent)
};

PreparedFrame prepareFrame(SlamPipeline& pipeline, const DatasetFrame& f, FrameFeatures& out) {
  const auto start = std::chrono::steady_clock::now();
  PreparedFrame p;
  p.error = f.error();
  pipeline.computeFeatures(f.view(), out, p.timing);
  p.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return p;
}

void progress(std::size_t done, std::size_t total, double ms_per_frame, const PoseEstimate& pose) {
  constexpr int kWidth = 32;
  const int filled = total ? static_cast<int>(kWidth * done / total) : kWidth;
  std::fprintf(stderr, "\r[%.*s%*s] %zu/%zu  %6.1f ms/frame  %-15s", filled, "################################",
               kWidth - filled, "", done, total, ms_per_frame, trackingStateName(pose.state));
  std::fflush(stderr);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mcslam-run: run multi-camera SLAM on a dataset (ASL/Kalibr, EuRoC or KITTI layout)"};
  std::string dataset_dir, calibration_path, config_path, cameras_text, out_path, keyframes_path, stats_path, extrinsics_path;
  bool quiet = false, print_config = false, overlap = true;
  std::string log_level = "info";
  std::size_t max_frames = 0;
  app.add_option("--dataset", dataset_dir, "Dataset folder (native ASL layout with camchain.yaml, EuRoC mav0/, or KITTI)")
      ->required();
  app.add_option("--config", config_path, "YAML file with a `slam:` section (see config/slam.yaml); defaults otherwise");
  app.add_option("--calibration", calibration_path,
                 "Calibration to use instead of the dataset's own (Kalibr YAML, EuRoC sensor.yaml, KITTI calib.txt)");
  app.add_option("--cameras", cameras_text, "Cameras of the rig to use, by calibration index, e.g. 0,1,2 (default: all)");
  app.add_option("--out", out_path, "Trajectory of every frame, TUM format (pose of the body in the world)");
  app.add_option("--keyframes", keyframes_path, "Keyframe poses, TUM format");
  app.add_option("--stats", stats_path, "Timing per stage (mean, p99) and tracking states, JSON");
  app.add_option("--extrinsics", extrinsics_path, "Camera extrinsics after online refinement, Kalibr camchain YAML");
  app.add_option("--frames", max_frames, "Process only the first N rig frames (0: all)");
  app.add_flag("--quiet", quiet, "No progress bar");
  app.add_option("--log-level", log_level, "Log of the pipeline's events (debug: also each scale estimate of a rig "
                                           "without overlap; trace: also every frame's tracking attempts, inliers, "
                                           "keyframes and new landmarks)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  app.add_flag("--overlap,!--no-overlap", overlap,
               "Run the front-end of the next frame while the odometry works on this one (the default; same output). "
               "--no-overlap: one stage after the other, which can be faster on a machine busy with other work "
               "(BENCHMARKS.md)");
  app.add_flag("--print-config", print_config,
               "Print the effective `slam:` configuration (defaults, --config, this dataset's rig) and exit");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(log_level));

  try {
    DatasetOptions dopt;
    if (!cameras_text.empty()) dopt.cameras = parseCameraList(cameras_text);
    dopt.calibration_override = calibration_path;
    const Dataset ds = Dataset::open(dataset_dir, dopt);
    for (const std::string& w : ds.warnings()) std::fprintf(stderr, "mcslam-run: warning: %s\n", w.c_str());
    if (ds.size() == 0) throw InputError(dataset_dir + ": the dataset has no frames");
    const PipelineConfig config = parsePipelineConfig(slamSection(config_path), config_path.empty() ? "defaults" : config_path,
                                                      ds.rig());
    if (print_config) {
      std::fputs(formatPipelineConfig(config).c_str(), stdout);
      return 0;
    }
    SlamPipeline pipeline(ds.rig(), config);
    const std::size_t frames = max_frames > 0 ? std::min(max_frames, ds.size()) : ds.size();
    run::RunReport report;
    const bool show = !quiet && ::isatty(STDERR_FILENO);
    if (!quiet) {
      std::fprintf(stderr, "mcslam-run: %s (%s), %d camera%s, %zu frames\n", dataset_dir.c_str(), ds.format().c_str(),
                   ds.rig().size(), ds.rig().size() == 1 ? "" : "s", frames);
    }

    // Images are decoded one frame ahead on their own thread. The front-end of frame i+1 runs after the odometry of
    // frame i or, by default (--overlap), during it (on another thread): the two stages share no state, so the output is the
    // same either way.
    FrameFeatures buffers[2] = {pipeline.makeFrameFeatures(), pipeline.makeFrameFeatures()};
    std::future<DatasetFrame> next_load = std::async(std::launch::async, loadFrame, std::cref(ds), std::size_t{0});
    auto frontEnd = [&](std::size_t i) {  // takes frame i's images and starts decoding frame i+1
      const DatasetFrame f = next_load.get();
      if (i + 1 < frames) next_load = std::async(std::launch::async, loadFrame, std::cref(ds), i + 1);
      return prepareFrame(pipeline, f, buffers[i % 2]);
    };
    const auto wall_start = std::chrono::steady_clock::now();
    std::future<PreparedFrame> pending;
    if (overlap) pending = std::async(std::launch::async, frontEnd, std::size_t{0});
    bool was_initialized = false;
    bool last_tracked_unscaled = false;  // the last tracked pose was not in metres
    double ms_avg = 0;
    for (std::size_t i = 0; i < frames; ++i) {
      PreparedFrame prepared = overlap ? pending.get() : frontEnd(i);
      if (overlap && i + 1 < frames) pending = std::async(std::launch::async, frontEnd, i + 1);
      if (!prepared.error.empty()) std::fprintf(stderr, "%smcslam-run: frame %zu: %s\n", show ? "\n" : "", i, prepared.error.c_str());
      PoseEstimate pose;
      PipelineTiming timing = prepared.timing;
      const auto track_start = std::chrono::steady_clock::now();
      pipeline.track(buffers[i % 2], i, ds.frames()[i].t, pose, timing);
      timing.total_ms = prepared.wall_ms + std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - track_start).count();
      // Losing and regaining track are worth a line of their own (the stats file lists them all).
      if (report.add(pose, timing) && !quiet && i > 0) {
        // Say when the poses are not in metres (pose.metric): a rig without overlap until its scale is found.
        const char* unit = pose.state != TrackingState::Tracking || pose.metric ? ""
                           : pipeline.odometry().trackingRig().size() == 1
                               ? " up to scale (one camera)"
                               : " up to scale (no two cameras overlap: the scale is searched in turns)";
        std::fprintf(stderr, "%smcslam-run: frame %zu (t = %.3f s): %s%s\n", show ? "\r\033[K" : "", i,
                     toSeconds(pose.t), trackingStateName(pose.state), unit);
      }
      const bool initialized = pipeline.odometry().initialized();
      if (initialized && !was_initialized && pipeline.odometry().lastInitializationReference() >= 0) {
        report.backfill(static_cast<uint64_t>(pipeline.odometry().lastInitializationReference()), i);
      }
      was_initialized = initialized;
      if (!quiet && pipeline.stats().scale_converged_frame == static_cast<int64_t>(i) && pose.valid) {
        std::fprintf(stderr, "%smcslam-run: frame %zu: metric scale found (sigma %.1f%%)\n", show ? "\r\033[K" : "", i,
                     100.0 * pipeline.stats().combined_scale_sigma);
      }
      if (pose.valid && pose.state == TrackingState::Tracking) last_tracked_unscaled = !pose.metric;
      if (pose.is_keyframe) report.noteKeyframes(pipeline.odometry().map());
      ms_avg = i == 0 ? timing.total_ms : 0.95 * ms_avg + 0.05 * timing.total_ms;
      if (show && (i % 5 == 0 || i + 1 == frames)) progress(i + 1, frames, ms_avg, pose);
    }
    pipeline.flush();  // the last keyframe's back-end solve
    report.noteKeyframes(pipeline.odometry().map());
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    if (show) std::fprintf(stderr, "\n");

    if (!out_path.empty()) writeTumTrajectory(out_path, report.trajectory());
    if (!keyframes_path.empty()) writeTumTrajectory(keyframes_path, report.keyframes());
    if (!stats_path.empty()) report.writeStats(stats_path, pipeline, dataset_dir, ds.rig().size(), wall);
    if (!extrinsics_path.empty()) writeKalibrRig(pipeline.refinedRig(), extrinsics_path);

    const OdometryStats& s = pipeline.stats();
    if (!quiet) {
      std::fprintf(stderr, "mcslam-run: %llu frames in %.1f s: %llu tracked, %llu lost, %llu not initialized, %llu keyframes\n",
                   static_cast<unsigned long long>(s.frames), wall, static_cast<unsigned long long>(s.tracking),
                   static_cast<unsigned long long>(s.lost), static_cast<unsigned long long>(s.not_initialized),
                   static_cast<unsigned long long>(s.keyframes));
      if (last_tracked_unscaled) {
        std::fprintf(stderr, "mcslam-run: %s: the trajectory's unit is arbitrary (evaluate it with --align sim3)\n",
                     pipeline.odometry().trackingRig().size() == 1 ? "one camera" : "the metric scale was not found");
      }
    }
  } catch (const InputError& e) {
    std::fprintf(stderr, "mcslam-run: %s\n", e.what());
    return 2;
  }
  return 0;
}
