#pragma once
// mcslamd's configuration file (docs/daemon.md lists every key). Parsing is strict: an unknown key, a
// wrong type, a zero capacity or an inconsistent combination throws InputError naming the file and the
// key, before anything starts. Relative paths are taken relative to the configuration file's folder.
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "aravis/aravis_config.hpp"
#include "daemon/rig_assembler.hpp"
#include "mcslam/calib/rig.hpp"
#include "sources/source_config.hpp"
#include "trigger/trigger_config.hpp"

namespace mcslam::platform {

struct AssemblyConfig {
  RigAssembler::MatchBy match_by = RigAssembler::MatchBy::TriggerCount;
  double tolerance_ms = 5;  // timestamp matching
  double timeout_ms = 200;  // a rig frame still incomplete after this goes out partial
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

// The place map kept across restarts (docs/daemon.md, "map"). Paths are relative to the output directory.
struct MapConfig {
  std::string load;                       // empty: start without one; a missing file: start a new one there
  std::string save;                       // empty: never saved
  double save_interval_s = 60;            // 0: only at a clean stop
  bool localize_only = false;             // mode localize: the loaded map is used, never changed (nor saved)
  bool start_without_unreadable = false;  // on_unreadable start_empty: set an unreadable map aside, start without
};

struct RealtimeConfig {
  int trigger_priority = 0;  // SCHED_FIFO 1..99, 0 = normal scheduling
  int acquisition_priority = 0;
  int processing_priority = 0;
  bool lock_memory = false;
  std::vector<int> cpus;  // the CPUs every thread of the daemon may run on (empty: any)
};

struct DaemonConfig {
  std::string file;  // the configuration file
  std::string log_level = "info";
  double status_interval_s = 1.0;
  double warmup_frames = 50;  // allocations are counted after this many processed frames
  SourceType source_type = SourceType::Dataset;
  std::string calibration;  // Kalibr camchain; optional for a dataset (it has its own)
  DatasetSourceConfig dataset;
  SimSourceConfig sim;
  AravisSourceConfig aravis;
  TriggerConfig trigger;
  AssemblyConfig assembly;
  CapacityConfig capacities;
  PublishConfig publish;
  OutputConfig output;
  MapConfig map;
  RealtimeConfig realtime;
  YAML::Node slam;  // handed to the pipeline factory
  Rig rig;          // resolved: calibration file, the dataset's own, or the simulated rig's cameras
};

// A finite source that stops the daemon when it has delivered its last frame (at_end: exit).
bool exitsAtEnd(const DaemonConfig& config);
// What the configured source takes from the rest of the configuration.
SourceContext sourceContext(const DaemonConfig& config);

// Parses and validates everything that needs no device (the rig is loaded; the dataset is opened
// only to read its rig and count). Throws InputError.
DaemonConfig loadDaemonConfig(const std::string& path);
DaemonConfig parseDaemonConfig(const std::string& yaml_text, const std::string& file);

// The effective configuration (defaults filled in, `slam:` through effectivePipelineConfig) as YAML.
std::string effectiveDaemonConfig(const DaemonConfig& config);

}  // namespace mcslam::platform
