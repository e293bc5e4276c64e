#pragma once
// The configuration of the sources (the `source:` section of mcslamd's configuration, read by the daemon's
// config reader), and what every source takes from the rest of the configuration (SourceContext).
#include <cstdint>
#include <string>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "trigger/trigger_config.hpp"

namespace mcslam::platform {

enum class SourceType { Dataset, Aravis, Sim };

enum class ReplayRate {
  Recorded,  // at the recorded time stamps, scaled by speed
  Fastest,   // lossless: the next frame as soon as the pipeline has taken the previous one
};

// What a finite source does after its last frame.
enum class AtEnd {
  Exit,  // the daemon stops once everything is processed
  Loop,  // starts again (capture times keep growing, so the trajectory stays ordered)
  Idle,  // stays up without frames
};

enum class SimPace {
  Fastest,   // lossless: the next frame is rendered as soon as the pipeline has taken the previous one
  Realtime,  // frame n is due n / rate_hz after the start; the newest due frame is rendered, the others skipped
};

struct DatasetSourceConfig {
  std::string path;
  ReplayRate rate = ReplayRate::Recorded;
  double speed = 1.0;
  AtEnd at_end = AtEnd::Exit;
  bool preload = false;  // decode every image at start (replay then allocates nothing)
  uint32_t max_preload_frames = 2000;
  std::vector<int> cameras;  // calibration indices to use (empty = all)
};

// Live rendering with the simulator (mcslam_sim): frames are rendered as they are due.
struct SimSourceConfig {
  std::string rig = "isec";           // preset (isec, stereo, mono, ring8) or Kalibr camchain file
  std::string world = "indoor";       // indoor | corridor | courtyard
  std::string trajectory = "ground";  // ground | handheld | file:PATH (TUM)
  double rate_hz = 10;                // simulated frame rate: the motion and the capture stamps
  int frames = 0;                     // 0: as many as the trajectory lasts
  uint64_t seed = 1;
  SimPace pace = SimPace::Fastest;
  AtEnd at_end = AtEnd::Loop;
  bool anti_aliasing = true;  // false: one ray per pixel, cheaper
  int render_threads = 0;     // 0: one per core
  std::vector<int> cameras;   // rig indices to render (empty = all)
};

// What a source needs besides its own section.
struct SourceContext {
  std::string file;              // the configuration file (error messages name it)
  Rig rig;                       // the rig being processed: one camera ring per camera, sized for its images
  TriggerConfig trigger;         // mode (software: the source is the trigger's output) and rate
  int acquisition_priority = 0;  // SCHED_FIFO priority of acquisition threads, 0 = normal scheduling
  std::string calibration;       // a dataset's calibration override (empty: the dataset's own)
};

}  // namespace mcslam::platform
