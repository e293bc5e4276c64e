// mcslam-run: runs the SLAM pipeline on a recorded dataset as fast as it can, and writes the trajectory of
// every frame, the keyframes, per-stage timing and tracking statistics.
#include <unistd.h>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <exception>
#include <future>
#include <string_view>
#include <system_error>
#include <thread>
#include <vector>

#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/alloc_counter.hpp"
#include "mcslam/core/config_section.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/core/synced_file.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/pipeline/dataset_frame.hpp"
#include "mcslam/pipeline/slam_pipeline.hpp"
#include "mcslam/pipeline/stage_runner.hpp"
#include "run_report.hpp"

using namespace mcslam;

namespace {

struct RunOptions {
  std::string dataset_dir, calibration_path, config_path, cameras_text;
  std::string out_path, keyframes_path, stats_path, frame_times_path, extrinsics_path;
  bool quiet = false, print_config = false, overlap = true;
  std::string log_level = "info";
  std::size_t max_frames = 0;
  std::string black_text, skip_text;  // fault injection: frame ranges "A-B,C,..."
  bool no_loop_closure = false;
  bool live = false;
  std::size_t first_frame = 0;
  std::string map_in, map_out;
  bool localize = false;
};

// Frame ranges "A-B" (both included) or "A", separated by commas; empty text: none. Throws InputError naming the
// option.
class FrameRanges {
 public:
  FrameRanges(const std::string& option, const std::string& text) {
    if (text.empty()) return;
    for (std::size_t begin = 0;;) {
      const std::size_t comma = text.find(',', begin);
      ranges_.push_back(parseOne(option, text, std::string_view(text).substr(begin, comma - begin)));
      if (comma == std::string::npos) break;
      begin = comma + 1;
    }
  }
  bool contains(std::size_t i) const {
    return std::any_of(ranges_.begin(), ranges_.end(), [i](const Range& r) { return i >= r.first && i <= r.last; });
  }

 private:
  struct Range {
    std::size_t first = 0, last = 0;
  };
  static Range parseOne(const std::string& option, const std::string& text, std::string_view range) {
    Range r;
    const char* end = range.data() + range.size();
    std::from_chars_result at = std::from_chars(range.data(), end, r.first);
    bool ok = at.ec == std::errc() && at.ptr != range.data();
    r.last = r.first;
    if (ok && at.ptr != end && *at.ptr == '-') {
      const char* second = at.ptr + 1;
      at = std::from_chars(second, end, r.last);
      ok = at.ec == std::errc() && at.ptr != second;
    }
    if (!ok || at.ptr != end || r.last < r.first)
      throw InputError(option + " '" + text + "': '" + std::string(range) +
                       "' is not a frame range: expected A-B with A <= B, or one frame A; ranges separated by commas");
    return r;
  }
  std::vector<Range> ranges_;
};

void addOptions(CLI::App& app, RunOptions& o) {
  app.add_option(
         "--dataset", o.dataset_dir,
         "Dataset folder (native ASL layout with camchain.yaml, EuRoC mav0/, KITTI odometry or KITTI raw drive)")
      ->required();
  app.add_option("--config", o.config_path,
                 "YAML file with a `slam:` section (see config/slam.yaml); defaults otherwise");
  app.add_option("--calibration", o.calibration_path,
                 "Calibration to use instead of the dataset's own (Kalibr YAML, EuRoC sensor.yaml, KITTI calib.txt)");
  app.add_option("--cameras", o.cameras_text,
                 "Cameras of the rig to use, by calibration index, e.g. 0,1,2 (default: all)");
  app.add_option("--out", o.out_path,
                 "Trajectory, TUM format (pose of the body in the world): every frame that has a pose (none before "
                 "the map is initialized, while lost, or while localizing in a loaded map); --stats counts them");
  app.add_option("--keyframes", o.keyframes_path, "Keyframe poses, TUM format");
  app.add_option("--stats", o.stats_path, "Timing per stage (mean, p99) and tracking states, JSON");
  app.add_option("--frame-times", o.frame_times_path,
                 "Each frame's stage times, tracking state and keyframe flag, CSV (which frames make the p99)");
  app.add_option("--extrinsics", o.extrinsics_path, "Camera extrinsics after online refinement, Kalibr camchain YAML");
  app.add_option("--frames", o.max_frames, "Process only the first N rig frames (0: all)");
  app.add_option("--start", o.first_frame, "Begin at rig frame N of the dataset (with --frames: N of them)");
  app.add_option("--map-in", o.map_in,
                 "Reuse this saved map: poses are in its frame from the first frame recognized in it (before that "
                 "the state is 'localizing' and no pose is written)");
  app.add_option("--map-out", o.map_out, "Save the place map at the end (written whole or not at all)");
  app.add_flag("--localize", o.localize, "With --map-in: localize in the map without changing it");
  app.add_flag("--quiet", o.quiet, "No progress bar");
  app.add_flag("--no-loop-closure", o.no_loop_closure,
               "Relocalize, but close no loop (places.loop_closure: false), for comparisons");
  app.add_flag("--live", o.live,
               "Take the loop closer's results as mcslamd does, the first frame they are ready, instead of waiting "
               "for them at fixed frames: runs no longer repeat exactly");
  app.add_option("--black", o.black_text,
                 "Fault injection: every camera's image of frames A-B (dataset indices; several ranges: A-B,C-D) is "
                 "black, as if the rig were covered");
  app.add_option("--skip", o.skip_text,
                 "Fault injection: frames A-B (several ranges: A-B,C-D) are never given to the SLAM (a kidnap: the rig "
                 "moved unseen; frames a camera dropped)");
  app.add_option("--log-level", o.log_level,
                 "Log of the pipeline's events (debug: also each scale estimate of a rig "
                 "without overlap; trace: also every frame's tracking attempts, inliers, "
                 "keyframes and new landmarks)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  app.add_flag("--overlap,!--no-overlap", o.overlap,
               "Run the front-end of the next frame while the odometry works on this one (the default; same output). "
               "--no-overlap: one stage after the other, which can be faster on a machine busy with other work "
               "(BENCHMARKS.md)");
  app.add_flag("--print-config", o.print_config,
               "Print the effective `slam:` configuration (defaults, --config, this dataset's rig) and exit");
}

// The `slam:` section of a config file; a file holding only the section's keys is accepted too.
YAML::Node slamSection(const std::string& path) {
  if (path.empty()) return YAML::Node();
  const YAML::Node root = parseYamlText(readTextFile(path, kMaxConfigFileBytes), path);
  if (root.IsMap() && root["slam"]) return root["slam"];
  return root;
}

// Decodes the dataset's frames one ahead, on a thread of its own: the front-end does not wait for the decoding.
class FramePrefetch {
 public:
  // Runs the dataset's frames `order[0], order[1], ...`; those in `black` become black.
  FramePrefetch(const Dataset& ds, const std::vector<std::size_t>& order, const FrameRanges& black)
      : ds_(ds), order_(order), frames_(order.size()), black_(black) {
    if (frames_ > 0) next_ = std::async(std::launch::async, load, std::cref(ds_), order_[0], std::cref(black_));
  }
  ~FramePrefetch() {
    if (next_.valid()) next_.wait();
  }
  // Frame i (called for i = 0, 1, ... in turn); starts decoding frame i + 1.
  DatasetFrame take(std::size_t i) {
    DatasetFrame f = next_.get();
    if (i + 1 < frames_) next_ = std::async(std::launch::async, load, std::cref(ds_), order_[i + 1], std::cref(black_));
    return f;
  }

 private:
  static DatasetFrame load(const Dataset& ds, std::size_t i, const FrameRanges& black) {
    DatasetFrame f;
    f.load(ds, i);
    if (black.contains(i)) f.blacken();
    return f;
  }
  const Dataset& ds_;
  const std::vector<std::size_t>& order_;
  std::size_t frames_;
  const FrameRanges& black_;
  std::future<DatasetFrame> next_;
};

// What the console shows while the run goes on: a progress bar, and a line for each change of tracking state
// and for the metric scale found.
class Console {
 public:
  Console(bool quiet, std::size_t frames) : quiet_(quiet), show_(!quiet && ::isatty(STDERR_FILENO)), frames_(frames) {}

  void frameError(std::size_t i, const std::string& error) const {
    if (!error.empty()) std::fprintf(stderr, "%smcslam-run: frame %zu: %s\n", show_ ? "\n" : "", i, error.c_str());
  }
  // Losing and regaining track are worth a line of their own (the stats file lists them all).
  void stateChanged(std::size_t i, const PoseEstimate& pose, int cameras) const {
    if (quiet_ || i == 0) return;
    // Say when the poses are not in metres (pose.metric): a rig without overlap until its scale is found, overlapping
    // cameras until they see enough near points.
    const char* unit = pose.state != TrackingState::Tracking || pose.metric ? ""
                       : cameras == 1                                       ? " up to scale (one camera)"
                       : pose.roughly_metric
                           ? " in roughly metric units (too few of the overlapping cameras' common points are near "
                             "enough for their baseline)"
                           : " up to scale (no two cameras overlap: the scale is searched in turns)";
    std::fprintf(stderr, "%smcslam-run: frame %zu (t = %.3f s): %s%s\n", show_ ? "\r\033[K" : "", i, toSeconds(pose.t),
                 trackingStateName(pose.state), unit);
  }
  // `sigma`: of the window estimates that found it; not finite when a roughly metric map saw enough near points.
  void scaleFound(std::size_t i, double sigma) const {
    if (quiet_) return;
    const char* clear = show_ ? "\r\033[K" : "";
    if (std::isfinite(sigma)) {
      std::fprintf(stderr, "%smcslam-run: frame %zu: metric scale found (sigma %.1f%%)\n", clear, i, 100.0 * sigma);
    } else {
      std::fprintf(stderr, "%smcslam-run: frame %zu: metric scale found (enough common points near the cameras)\n",
                   clear, i);
    }
  }
  void progress(std::size_t i, double total_ms, const PoseEstimate& pose) {
    ms_avg_ = i == 0 ? total_ms : 0.95 * ms_avg_ + 0.05 * total_ms;
    if (!show_ || (i % 5 != 0 && i + 1 != frames_)) return;
    constexpr int kWidth = 32;
    const std::size_t done = i + 1;
    const int filled = frames_ ? static_cast<int>(kWidth * done / frames_) : kWidth;
    std::fprintf(stderr, "\r[%.*s%*s] %zu/%zu  %6.1f ms/frame  %-15s", filled, "################################",
                 kWidth - filled, "", done, frames_, ms_avg_, trackingStateName(pose.state));
    std::fflush(stderr);
  }
  void endProgress() const {
    if (show_) std::fprintf(stderr, "\n");
  }

 private:
  bool quiet_, show_;
  std::size_t frames_;
  double ms_avg_ = 0;
};

// What the front-end side hands to the tracking side with each frame.
struct FrameTag {
  std::string error;  // an unreadable image (its camera is then absent)
};

// Runs the first `frames` frames through the pipeline's stages (StageRunner): the front-end of frame i+1 on a
// thread of its own while frame i is tracked on this one, or, without `overlap`, one after the other on this
// thread. The stages share no state, so the output is the same either way. Returns the wall time in seconds.
double runFrames(SlamPipeline& pipeline, const Dataset& ds, const std::vector<std::size_t>& order,
                 const FrameRanges& black, bool overlap, run::RunReport& report, Console& console) {
  const std::size_t frames = order.size();
  StageRunner<FrameTag> runner(pipeline);
  FramePrefetch prefetch(ds, order, black);
  // Frames after the warm-up (the daemon's default) count the pipeline's allocations: none is the rule.
  constexpr std::size_t kWarmupFrames = 50;
  run::AllocationCount allocations{alloc::available(), kWarmupFrames};
  std::atomic<uint64_t> front_end_allocations{0};
  uint64_t background_at_warmup = 0;
  auto prepare = [&](std::size_t i) {
    const DatasetFrame f = prefetch.take(i);
    const alloc::ThreadScope scope;
    runner.prepare(f.view(), FrameTag{f.error()});
    if (i >= kWarmupFrames) front_end_allocations += scope.count();
  };
  const auto wall_start = std::chrono::steady_clock::now();
  std::exception_ptr front_end_error;
  std::thread front_end;
  if (overlap) {
    front_end = std::thread([&] {
      try {
        for (std::size_t i = 0; i < frames; ++i) prepare(i);
      } catch (...) {
        front_end_error = std::current_exception();
      }
      runner.close();
    });
  }
  bool was_initialized = false;
  std::vector<KeyframePose> keyframes;
  for (std::size_t i = 0; i < frames; ++i) {
    if (!overlap) prepare(i);
    PoseEstimate pose;
    FrameTag tag;
    if (i == kWarmupFrames) background_at_warmup = pipeline.backgroundThreadAllocations();
    const alloc::ThreadScope scope;
    if (!runner.finish(pose, tag)) break;  // the front-end failed (rethrown below)
    if (i >= kWarmupFrames) allocations.tracking += scope.count();
    console.frameError(i, tag.error);
    const PipelineTiming& timing = pipeline.timing();
    if (report.add(pose, timing)) console.stateChanged(i, pose, pipeline.cameras());
    const bool map_started = pipeline.initialized() && !was_initialized;
    if (map_started) report.backfill(pipeline.initialization(), i);
    was_initialized = pipeline.initialized();
    if (pipeline.stats().scale_converged_frame == static_cast<int64_t>(i) && pose.valid) {
      console.scaleFound(i, pipeline.stats().combined_scale_sigma);
    }
    if (pose.is_keyframe || map_started) {  // a start from two frames is seen a frame after its keyframe
      pipeline.keyframes(keyframes);
      report.noteKeyframes(keyframes);
    }
    console.progress(i, timing.total_ms, pose);
  }
  if (front_end.joinable()) front_end.join();
  if (front_end_error) std::rethrow_exception(front_end_error);
  pipeline.flush();  // the last keyframe's back-end solve
  if (frames > kWarmupFrames) allocations.background = pipeline.backgroundThreadAllocations() - background_at_warmup;
  allocations.front_end = front_end_allocations;
  report.setAllocations(allocations);
  pipeline.keyframes(keyframes);
  report.noteKeyframes(keyframes);
  console.endProgress();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
}

void printSummary(const SlamPipeline& pipeline, const run::RunReport& report, double wall) {
  const OdometryStats& s = pipeline.stats();
  std::fprintf(stderr,
               "mcslam-run: %llu frames in %.1f s: %llu tracked, %llu lost, %llu not initialized, %llu keyframes\n",
               static_cast<unsigned long long>(s.frames), wall, static_cast<unsigned long long>(s.tracking),
               static_cast<unsigned long long>(s.lost), static_cast<unsigned long long>(s.not_initialized),
               static_cast<unsigned long long>(s.keyframes));
  if (report.lastTrackedRoughlyMetric()) {
    std::fprintf(stderr,
                 "mcslam-run: the overlapping cameras never saw enough common points near enough for their baseline: "
                 "the trajectory's unit is the metre to within tens of percent (evaluate it with --align sim3)\n");
  } else if (report.lastTrackedUnscaled()) {
    std::fprintf(stderr, "mcslam-run: %s: the trajectory's unit is arbitrary (evaluate it with --align sim3)\n",
                 pipeline.cameras() == 1 ? "one camera" : "the metric scale was not found");
  }
}

void saveMap(const SlamPipeline& pipeline, const std::string& path) {
  std::string bytes, error;
  if (!pipeline.writeMap(bytes)) throw InputError("--map-out: there is no map to save: places.enabled is false");
  if (!writeFileSynced(path, bytes, &error)) throw InputError("--map-out: " + error);
}

int runDataset(const RunOptions& o) {
  DatasetOptions dopt;
  if (!o.cameras_text.empty()) dopt.cameras = parseCameraList(o.cameras_text);
  dopt.calibration_override = o.calibration_path;
  const Dataset ds = Dataset::open(o.dataset_dir, dopt);
  for (const std::string& w : ds.warnings()) std::fprintf(stderr, "mcslam-run: warning: %s\n", w.c_str());
  if (ds.size() == 0) throw InputError(o.dataset_dir + ": the dataset has no frames");
  PipelineConfig config =
      parsePipelineConfig(slamSection(o.config_path), o.config_path.empty() ? "defaults" : o.config_path, ds.rig());
  if (o.no_loop_closure) config.places.loop_closure = false;
  config.places.repeatable = !o.live;
  if (o.localize && o.map_in.empty()) throw InputError("--localize needs a map to localize in (--map-in)");
  if (o.localize && !o.map_out.empty())
    throw InputError("--map-out with --localize: a map only localized in is not changed, there is nothing to save");
  if (o.print_config) {
    std::fputs(formatPipelineConfig(config).c_str(), stdout);
    return 0;
  }
  SlamPipeline pipeline(ds.rig(), config);
  if (!o.map_in.empty()) pipeline.loadMap(o.map_in, o.localize);
  if (o.first_frame >= ds.size())
    throw InputError("--start " + std::to_string(o.first_frame) + ": the dataset has " + std::to_string(ds.size()) +
                     " frames");
  const std::size_t available = ds.size() - o.first_frame;
  const std::size_t frames = o.first_frame + (o.max_frames > 0 ? std::min(o.max_frames, available) : available);
  const FrameRanges black("--black", o.black_text);
  const FrameRanges skip("--skip", o.skip_text);
  std::vector<std::size_t> order;
  for (std::size_t i = o.first_frame; i < frames; ++i)
    if (!skip.contains(i)) order.push_back(i);
  if (!o.quiet) {
    std::fprintf(stderr, "mcslam-run: %s (%s), %d camera%s, %zu frames\n", o.dataset_dir.c_str(), ds.format().c_str(),
                 ds.rig().size(), ds.rig().size() == 1 ? "" : "s", order.size());
  }
  run::RunReport report;
  Console console(o.quiet, order.size());
  const double wall = runFrames(pipeline, ds, order, black, o.overlap, report, console);
  if (!o.out_path.empty()) writeTumTrajectory(o.out_path, report.trajectory());
  if (!o.keyframes_path.empty()) writeTumTrajectory(o.keyframes_path, report.keyframes());
  if (!o.stats_path.empty()) report.writeStats(o.stats_path, pipeline, o.dataset_dir, ds.rig().size(), wall);
  if (!o.frame_times_path.empty()) report.writeFrameTimes(o.frame_times_path, order);
  if (!o.extrinsics_path.empty()) writeKalibrRig(pipeline.refinedRig(), o.extrinsics_path);
  if (!o.map_out.empty()) saveMap(pipeline, o.map_out);
  if (!o.quiet) printSummary(pipeline, report, wall);
  if (report.trajectory().empty()) {
    std::fprintf(stderr,
                 "mcslam-run: error: no frame of %zu got a pose (the map never initialized, or the run never "
                 "recognized where it is in the loaded map); the trajectory is empty\n",
                 order.size());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mcslam-run: run multi-camera SLAM on a dataset (ASL/Kalibr, EuRoC, KITTI odometry or raw layout)"};
  RunOptions options;
  addOptions(app, options);
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(options.log_level));
  // What glibc would set up on the first log line, done now: a line logged mid-run (a relocalization) then
  // allocates nothing.
  static char log_buffer[BUFSIZ];
  std::setvbuf(stdout, log_buffer, _IOLBF, sizeof(log_buffer));
  tzset();
  try {
    return runDataset(options);
  } catch (const InputError& e) {
    std::fprintf(stderr, "mcslam-run: %s\n", e.what());
    return 2;
  }
}
