// effectiveDaemonConfig: the configuration as --check-config prints it, every key with its effective value.
#include <cstdio>
#include <sstream>

#include "daemon/config_names.hpp"
#include "daemon/daemon_config.hpp"
#include "mcslam/pipeline/pipeline_factory.hpp"

namespace mcslam::platform {

namespace {

void emitDataset(YAML::Emitter& e, const DatasetSourceConfig& d) {
  e << YAML::Key << "dataset" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "path" << YAML::Value << d.path << YAML::Key << "rate" << YAML::Value << configName(d.rate);
  e << YAML::Key << "speed" << YAML::Value << d.speed << YAML::Key << "at_end" << YAML::Value << configName(d.at_end);
  e << YAML::Key << "preload" << YAML::Value << d.preload;
  e << YAML::Key << "max_preload_frames" << YAML::Value << d.max_preload_frames;
  e << YAML::Key << "cameras" << YAML::Value << YAML::Flow << d.cameras;
  e << YAML::EndMap;
}

void emitSim(YAML::Emitter& e, const SimSourceConfig& m) {
  e << YAML::Key << "sim" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "rig" << YAML::Value << m.rig << YAML::Key << "world" << YAML::Value << m.world;
  e << YAML::Key << "trajectory" << YAML::Value << m.trajectory << YAML::Key << "rate_hz" << YAML::Value << m.rate_hz;
  e << YAML::Key << "frames" << YAML::Value << m.frames << YAML::Key << "seed" << YAML::Value << m.seed;
  e << YAML::Key << "pace" << YAML::Value << configName(m.pace) << YAML::Key << "at_end" << YAML::Value
    << configName(m.at_end);
  e << YAML::Key << "anti_aliasing" << YAML::Value << m.anti_aliasing;
  e << YAML::Key << "render_threads" << YAML::Value << m.render_threads;
  e << YAML::Key << "cameras" << YAML::Value << YAML::Flow << m.cameras;
  e << YAML::EndMap;
}

void emitAravis(YAML::Emitter& e, const AravisSourceConfig& a) {
  e << YAML::Key << "aravis" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "stream_buffers" << YAML::Value << a.stream_buffers;
  e << YAML::Key << "packet_size" << YAML::Value << a.packet_size;
  e << YAML::Key << "frame_timeout_ms" << YAML::Value << a.frame_timeout_ms;
  e << YAML::Key << "cameras" << YAML::Value << YAML::BeginSeq;
  for (const auto& cam : a.cameras) {
    e << YAML::BeginMap << YAML::Key << "id" << YAML::Value << cam.id;
    e << YAML::Key << "exposure_us" << YAML::Value << cam.exposure_us;
    e << YAML::Key << "gain_db" << YAML::Value << cam.gain_db;
    e << YAML::Key << "pixel_format" << YAML::Value << cam.pixel_format;
    e << YAML::Key << "trigger_line" << YAML::Value << cam.trigger_line << YAML::EndMap;
  }
  e << YAML::EndSeq << YAML::EndMap;
}

void emitSource(YAML::Emitter& e, const DaemonConfig& c) {
  e << YAML::Key << "source" << YAML::Value << YAML::BeginMap << YAML::Key << "type" << YAML::Value
    << configName(c.source_type);
  switch (c.source_type) {
    case SourceType::Dataset: emitDataset(e, c.dataset); break;
    case SourceType::Sim: emitSim(e, c.sim); break;
    case SourceType::Aravis: emitAravis(e, c.aravis); break;
  }
  e << YAML::EndMap;
}

void emitTriggerAndAssembly(YAML::Emitter& e, const DaemonConfig& c) {
  const auto& t = c.trigger;
  e << YAML::Key << "trigger" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "mode" << YAML::Value << configName(t.mode) << YAML::Key << "rate_hz" << YAML::Value << t.rate_hz;
  e << YAML::Key << "gpio_chip" << YAML::Value << t.gpio_chip << YAML::Key << "gpio_line" << YAML::Value << t.gpio_line;
  e << YAML::Key << "pulse_us" << YAML::Value << t.pulse_us << YAML::Key << "active_low" << YAML::Value << t.active_low;
  e << YAML::EndMap;
  e << YAML::Key << "assembly" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "match_by" << YAML::Value << configName(c.assembly.match_by);
  e << YAML::Key << "tolerance_ms" << YAML::Value << c.assembly.tolerance_ms;
  e << YAML::Key << "timeout_ms" << YAML::Value << c.assembly.timeout_ms << YAML::EndMap;
  const auto& k = c.capacities;
  e << YAML::Key << "capacities" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "max_cameras" << YAML::Value << k.max_cameras;
  e << YAML::Key << "camera_ring_slots" << YAML::Value << k.camera_ring_slots;
  e << YAML::Key << "pending_rig_frames" << YAML::Value << k.pending_rig_frames;
  e << YAML::Key << "rig_ring_slots" << YAML::Value << k.rig_ring_slots;
  e << YAML::Key << "pose_ring_slots" << YAML::Value << k.pose_ring_slots << YAML::EndMap;
}

void emitOutputs(YAML::Emitter& e, const DaemonConfig& c) {
  char mode[8];
  std::snprintf(mode, sizeof(mode), "%04o", c.publish.shm_mode);
  e << YAML::Key << "publish" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "shm" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "enabled" << YAML::Value << c.publish.shm_enabled;
  e << YAML::Key << "name" << YAML::Value << c.publish.shm_name;
  e << YAML::Key << "mode" << YAML::Value << YAML::DoubleQuoted << std::string(mode);
  e << YAML::Key << "ring_length" << YAML::Value << c.publish.shm_ring_length << YAML::EndMap;
  e << YAML::Key << "udp" << YAML::Value << YAML::BeginMap << YAML::Key << "destinations" << YAML::Value << YAML::Flow
    << c.publish.udp_destinations << YAML::EndMap;
  e << YAML::EndMap;
  e << YAML::Key << "output" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "directory" << YAML::Value << c.output.directory;
  e << YAML::Key << "trajectory" << YAML::Value << c.output.trajectory;
  e << YAML::Key << "extrinsics" << YAML::Value << c.output.extrinsics << YAML::EndMap;
  e << YAML::Key << "map" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "load" << YAML::Value << c.map.load;
  e << YAML::Key << "save" << YAML::Value << c.map.save;
  e << YAML::Key << "save_interval_s" << YAML::Value << c.map.save_interval_s;
  e << YAML::Key << "mode" << YAML::Value << (c.map.localize_only ? "localize" : "slam");
  e << YAML::Key << "on_unreadable" << YAML::Value << (c.map.start_without_unreadable ? "start_empty" : "stop")
    << YAML::EndMap;
  const auto& r = c.realtime;
  e << YAML::Key << "realtime" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "trigger_priority" << YAML::Value << r.trigger_priority;
  e << YAML::Key << "acquisition_priority" << YAML::Value << r.acquisition_priority;
  e << YAML::Key << "processing_priority" << YAML::Value << r.processing_priority;
  e << YAML::Key << "lock_memory" << YAML::Value << r.lock_memory;
  e << YAML::Key << "cpus" << YAML::Value << YAML::Flow << r.cpus << YAML::EndMap;
}

}  // namespace

std::string effectiveDaemonConfig(const DaemonConfig& c) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "log_level" << YAML::Value << c.log_level;
  e << YAML::Key << "status_interval_s" << YAML::Value << c.status_interval_s;
  e << YAML::Key << "warmup_frames" << YAML::Value << static_cast<long long>(c.warmup_frames);
  e << YAML::Key << "calibration" << YAML::Value << c.calibration;
  emitSource(e, c);
  emitTriggerAndAssembly(e, c);
  emitOutputs(e, c);
  e << YAML::EndMap;
  std::ostringstream os;
  os << e.c_str() << "\n";
  os << "# rig: " << c.rig.size() << " camera(s)\n";
  os << effectivePipelineConfig(c.slam, c.file, c.rig);
  return os.str();
}

}  // namespace mcslam::platform
