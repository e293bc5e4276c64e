#pragma once
// mcslamd's configuration file (docs/daemon.md lists every key). Parsing is strict: an unknown key, a
// wrong type, a zero capacity or an inconsistent combination throws InputError naming the file and the
// key, before anything starts. Relative paths are taken relative to the configuration file's folder.
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "mcslam/calib/rig.hpp"

namespace mcslam::platform {

struct DatasetSourceConfig {
  std::string path;
  std::string rate = "recorded";  // recorded (its time stamps, scaled by speed) | fastest
  double speed = 1.0;
  std::string at_end = "exit";    // exit | loop | idle
  bool preload = false;           // decode every image at start (replay then allocates nothing)
  uint32_t max_preload_frames = 2000;
  std::vector<int> cameras;       // calibration indices to use (empty = all)
};

// Live rendering with the simulator (mcslam_sim): frames are rendered as they are due.
struct SimSourceConfig {
  std::string rig = "isec";           // preset (isec, stereo, mono, ring8) or Kalibr camchain file
  std::string world = "indoor";       // indoor | corridor | courtyard
  std::string trajectory = "ground";  // ground | handheld | file:PATH (TUM)
  double rate_hz = 10;                // simulated frame rate: the motion and the capture stamps
  int frames = 0;                     // 0: as many as the trajectory lasts
  uint64_t seed = 1;
  std::string pace = "fastest";       // fastest (lossless, as the pipeline takes frames) | realtime
  std::string at_end = "loop";        // exit | loop | idle
  bool anti_aliasing = true;          // false: one ray per pixel, cheaper
  int render_threads = 0;             // 0: one per core
  std::vector<int> cameras;           // rig indices to render (empty = all)
};

struct AravisCameraConfig {
  std::string id;              // serial number, device ID or IP address
  double exposure_us = 0;      // 0 = leave as configured on the camera
  double gain_db = -1;         // < 0 = leave
  std::string pixel_format = "Mono8";  // Mono8 | BayerRG8 | BayerGR8 | BayerGB8 | BayerBG8
  std::string trigger_line = "Line1";  // camera input wired to the GPIO pulse (trigger.mode gpio)
};

struct AravisSourceConfig {
  std::vector<AravisCameraConfig> cameras;  // in calibration order
  uint32_t stream_buffers = 8;
  int packet_size = 0;           // GigE packet size, 0 = negotiate
  double frame_timeout_ms = 1000;  // no frame for this long: the camera counts as lost and is reopened
};

struct TriggerConfig {
  std::string mode = "free_running";  // free_running | software | gpio
  double rate_hz = 20;
  std::string gpio_chip;  // gpiochipN, /dev/gpiochipN, label or number
  int gpio_line = -1;
  int pulse_us = 100;
  bool active_low = false;
};

struct AssemblyConfig {
  std::string match_by = "trigger_count";  // trigger_count | timestamp
  double tolerance_ms = 5;                 // timestamp matching
  double timeout_ms = 200;                 // a rig frame still incomplete after this goes out partial
};

struct CapacityConfig {
  uint32_t max_cameras = 8;
  uint32_t camera_ring_slots = 4;   // per camera, acquisition -> assembly
  uint32_t pending_rig_frames = 4;  // rig frames being assembled at once
  uint32_t rig_ring_slots = 2;      // assembly -> processing (the oldest is dropped when full)
  uint32_t pose_ring_slots = 64;    // processing -> publishing
};

struct PublishConfig {
  bool shm_enabled = true;
  std::string shm_name = "/mcslam_pose";
  unsigned shm_mode = 0644;
  uint32_t shm_ring_length = 256;
  std::vector<std::string> udp_destinations;  // host:port
};

struct OutputConfig {
  std::string directory;  // empty: $STATE_DIRECTORY, else the working directory
  std::string trajectory = "trajectory.tum";
  std::string extrinsics = "extrinsics.yaml";
};

struct RealtimeConfig {
  int trigger_priority = 0;  // SCHED_FIFO 1..99, 0 = normal scheduling
  int acquisition_priority = 0;
  int processing_priority = 0;
  bool lock_memory = false;
};

struct DaemonConfig {
  std::string file;  // the configuration file
  std::string log_level = "info";
  double status_interval_s = 1.0;
  double warmup_frames = 50;  // allocations are counted after this many processed frames
  std::string source_type;   // dataset | aravis | sim
  std::string calibration;   // Kalibr camchain; optional for a dataset (it has its own)
  DatasetSourceConfig dataset;
  SimSourceConfig sim;
  AravisSourceConfig aravis;
  TriggerConfig trigger;
  AssemblyConfig assembly;
  CapacityConfig capacities;
  PublishConfig publish;
  OutputConfig output;
  RealtimeConfig realtime;
  YAML::Node slam;  // handed to the pipeline factory
  Rig rig;          // resolved: calibration file, the dataset's own, or the simulated rig's cameras
};

// A finite source that stops the daemon when it has delivered its last frame (at_end: exit).
bool exitsAtEnd(const DaemonConfig& config);

// Parses and validates everything that needs no device (the rig is loaded; the dataset is opened
// only to read its rig and count). Throws InputError.
DaemonConfig loadDaemonConfig(const std::string& path);
DaemonConfig parseDaemonConfig(const std::string& yaml_text, const std::string& file);

// The effective configuration (defaults filled in, `slam:` through effectivePipelineConfig) as YAML.
std::string effectiveDaemonConfig(const DaemonConfig& config);

}  // namespace mcslam::platform
