#include "daemon/daemon_config.hpp"

#include <algorithm>
#include <filesystem>
#include <limits>
#include <sstream>

#include "daemon/config_names.hpp"
#include "daemon/yaml_fields.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/config_section.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/pipeline/pipeline_factory.hpp"
#include "mcslam/sim/rig_presets.hpp"
#include "mcslam/sim/world.hpp"
#include "realtime/scheduling.hpp"
#include "shm/pose_shm_writer.hpp"
#include "udp/udp_pose_sender.hpp"

namespace mcslam::platform {

namespace {

std::string resolvePath(const std::string& file, const std::string& path) {
  if (path.empty() || std::filesystem::path(path).is_absolute()) return path;
  const auto dir = std::filesystem::path(file).parent_path();
  return (dir.empty() ? std::filesystem::path(path) : dir / path).lexically_normal().string();
}

// A list of small non-negative integers under `key` (empty when absent): `what` says what each item is.
std::vector<int> readIndexList(const YamlFields& f, const char* key, const std::string& what, int max) {
  std::vector<int> list;
  if (!f.has(key)) return list;
  const YAML::Node n = f.node(key);
  if (!n.IsSequence()) f.fail(key, "expected a list of " + what + (what.back() == 'x' ? "es" : "s"));
  for (std::size_t i = 0; i < n.size(); ++i) {
    int v = 0;
    if (!n[i].IsScalar() || !YAML::convert<int>::decode(n[i], v) || v < 0 || v > max)
      f.fail(key, "item " + std::to_string(i) + " must be a " + what +
                      (max == std::numeric_limits<int>::max() ? " >= 0" : " from 0 to " + std::to_string(max)));
    list.push_back(v);
  }
  return list;
}

std::vector<int> readCameraList(const YamlFields& f) {
  return readIndexList(f, "cameras", "camera index", std::numeric_limits<int>::max());
}

void readSim(const YamlFields& f, SimSourceConfig& s) {
  f.allowOnly({"rig", "world", "trajectory", "rate_hz", "frames", "seed", "pace", "at_end", "anti_aliasing",
               "render_threads", "cameras"});
  s.rig = f.string("rig", s.rig);
  const auto presets = sim::rigPresetNames();
  if (std::find(presets.begin(), presets.end(), s.rig) == presets.end()) s.rig = resolvePath(f.file(), s.rig);
  const auto worlds = sim::worldNames();
  s.world = f.string("world", s.world);
  if (std::find(worlds.begin(), worlds.end(), s.world) == worlds.end()) {
    std::string known;
    for (const auto& w : worlds) known += (known.empty() ? "" : ", ") + w;
    f.fail("world", "'" + s.world + "' is not one of " + known);
  }
  s.trajectory = f.string("trajectory", s.trajectory);
  if (s.trajectory.rfind("file:", 0) == 0) {
    s.trajectory = "file:" + resolvePath(f.file(), s.trajectory.substr(5));
  } else if (s.trajectory != "ground" && s.trajectory != "handheld") {
    f.fail("trajectory", "'" + s.trajectory + "' is not one of ground, handheld, file:PATH");
  }
  s.rate_hz = f.positiveNumber("rate_hz", s.rate_hz);
  if (s.rate_hz > 1000) f.fail("rate_hz", "at most 1000 Hz, got " + std::to_string(s.rate_hz));
  s.frames = static_cast<int>(f.integer("frames", s.frames, 0, 100000000));
  s.seed = static_cast<uint64_t>(f.integer("seed", static_cast<long long>(s.seed), 0, 1ll << 62));
  s.pace = f.choice("pace", s.pace, kSimPaceNames);
  s.at_end = f.choice("at_end", s.at_end, kAtEndNames);
  s.anti_aliasing = f.boolean("anti_aliasing", s.anti_aliasing);
  s.render_threads = static_cast<int>(f.integer("render_threads", s.render_threads, 0, 256));
  s.cameras = readCameraList(f);
}

void readDataset(const YamlFields& f, DatasetSourceConfig& d) {
  f.allowOnly({"path", "rate", "speed", "at_end", "preload", "max_preload_frames", "cameras"});
  d.path = resolvePath(f.file(), f.requiredString("path"));
  d.rate = f.choice("rate", d.rate, kReplayRateNames);
  d.speed = f.positiveNumber("speed", d.speed);
  d.at_end = f.choice("at_end", d.at_end, kAtEndNames);
  d.preload = f.boolean("preload", d.preload);
  d.max_preload_frames = f.capacity("max_preload_frames", d.max_preload_frames);
  d.cameras = readCameraList(f);
}

void readAravis(const YamlFields& f, AravisSourceConfig& a) {
  f.allowOnly({"cameras", "stream_buffers", "packet_size", "frame_timeout_ms"});
  a.stream_buffers = f.capacity("stream_buffers", a.stream_buffers, 256);
  a.packet_size = static_cast<int>(f.integer("packet_size", a.packet_size, 0, 65535));
  a.frame_timeout_ms = f.positiveNumber("frame_timeout_ms", a.frame_timeout_ms);
  const YAML::Node list = f.node("cameras");
  if (!list || !list.IsSequence() || list.size() == 0)
    f.fail("cameras", "expected a non-empty list of cameras (each with at least 'id')");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YamlFields c(list[i], f.keyName("cameras") + "[" + std::to_string(i) + "]", f.file());
    c.allowOnly({"id", "exposure_us", "gain_db", "pixel_format", "trigger_line"});
    AravisCameraConfig cam;
    cam.id = c.requiredString("id");
    cam.exposure_us = c.number("exposure_us", cam.exposure_us);
    if (cam.exposure_us < 0) c.fail("exposure_us", "must be >= 0 (0 = leave the camera's setting)");
    cam.gain_db = c.number("gain_db", cam.gain_db);
    cam.pixel_format =
        c.choice("pixel_format", cam.pixel_format, {"Mono8", "BayerRG8", "BayerGR8", "BayerGB8", "BayerBG8"});
    cam.trigger_line = c.string("trigger_line", cam.trigger_line);
    a.cameras.push_back(cam);
  }
}

void readTrigger(const YamlFields& f, TriggerConfig& t) {
  f.allowOnly({"mode", "rate_hz", "gpio_chip", "gpio_line", "pulse_us", "active_low"});
  t.mode = f.choice("mode", t.mode, kTriggerModeNames);
  t.rate_hz = f.positiveNumber("rate_hz", t.rate_hz);
  if (t.rate_hz > 1000) f.fail("rate_hz", "at most 1000 Hz, got " + std::to_string(t.rate_hz));
  t.gpio_chip = f.string("gpio_chip", t.gpio_chip);
  t.gpio_line = static_cast<int>(f.integer("gpio_line", t.gpio_line, -1, 4095));
  t.pulse_us = static_cast<int>(f.integer("pulse_us", t.pulse_us, 1, 100000));
  t.active_low = f.boolean("active_low", t.active_low);
  if (t.mode == TriggerMode::Gpio) {
    if (t.gpio_chip.empty()) f.fail("gpio_chip", "required when trigger.mode is gpio");
    if (t.gpio_line < 0) f.fail("gpio_line", "required when trigger.mode is gpio");
    if (t.pulse_us * 1e-6 >= 1.0 / t.rate_hz) f.fail("pulse_us", "the pulse must be shorter than the trigger period");
  }
}

void readSource(const YamlFields& top, DaemonConfig& c) {
  const YamlFields source = top.child("source");
  source.allowOnly({"type", "dataset", "aravis", "sim"});
  if (!source.has("type")) source.fail("type", "missing (required): dataset, aravis or sim");
  c.source_type = source.choice("type", c.source_type, kSourceTypeNames);
  for (const SourceType other : {SourceType::Dataset, SourceType::Aravis, SourceType::Sim}) {
    if (c.source_type != other && source.has(configName(other)))
      source.fail(configName(other), std::string("given but source.type is ") + configName(c.source_type));
  }
  switch (c.source_type) {
    case SourceType::Dataset: readDataset(source.child("dataset"), c.dataset); break;
    case SourceType::Aravis: readAravis(source.child("aravis"), c.aravis); break;
    case SourceType::Sim: readSim(source.child("sim"), c.sim); break;
  }
}

void readAssembly(const YamlFields& f, AssemblyConfig& a) {
  f.allowOnly({"match_by", "tolerance_ms", "timeout_ms"});
  a.match_by = f.choice("match_by", a.match_by, kMatchByNames);
  a.tolerance_ms = f.positiveNumber("tolerance_ms", a.tolerance_ms);
  a.timeout_ms = f.positiveNumber("timeout_ms", a.timeout_ms);
}

void readCapacities(const YamlFields& f, CapacityConfig& k) {
  f.allowOnly({"max_cameras", "camera_ring_slots", "pending_rig_frames", "rig_ring_slots", "pose_ring_slots"});
  k.max_cameras = f.capacity("max_cameras", k.max_cameras, 64);
  k.camera_ring_slots = f.capacity("camera_ring_slots", k.camera_ring_slots, 1024);
  k.pending_rig_frames = f.capacity("pending_rig_frames", k.pending_rig_frames, 64);
  k.rig_ring_slots = f.capacity("rig_ring_slots", k.rig_ring_slots, 1024);
  k.pose_ring_slots = f.capacity("pose_ring_slots", k.pose_ring_slots, 65536);
}

void readPublish(const YamlFields& pub, PublishConfig& p) {
  pub.allowOnly({"shm", "udp"});
  const YamlFields shm = pub.child("shm");
  shm.allowOnly({"enabled", "name", "mode", "ring_length"});
  p.shm_enabled = shm.boolean("enabled", p.shm_enabled);
  p.shm_name = shm.string("name", p.shm_name);
  if (p.shm_name.size() < 2 || p.shm_name[0] != '/' || p.shm_name.find('/', 1) != std::string::npos)
    shm.fail("name", "'" + p.shm_name + "' must be '/' followed by a name without '/'");
  p.shm_mode = shm.permissions("mode", p.shm_mode);
  if (const std::string why = shmModeProblem(p.shm_mode); !why.empty()) shm.fail("mode", why);
  p.shm_ring_length = shm.capacity("ring_length", p.shm_ring_length, 1u << 20);
  const YamlFields udp = pub.child("udp");
  udp.allowOnly({"destinations"});
  p.udp_destinations = udp.stringList("destinations");
  for (const auto& d : p.udp_destinations) resolveUdpDestination(d, pub.file() + ": " + udp.keyName("destinations"));
}

void readOutput(const YamlFields& out, OutputConfig& o) {
  out.allowOnly({"directory", "trajectory", "extrinsics"});
  o.directory = resolvePath(out.file(), out.string("directory", ""));
  o.trajectory = out.string("trajectory", o.trajectory);
  o.extrinsics = out.string("extrinsics", o.extrinsics);
  if (o.trajectory.empty()) out.fail("trajectory", "must not be empty");
}

void readMap(const YamlFields& m, MapConfig& c) {
  m.allowOnly({"load", "save", "save_interval_s", "mode", "on_unreadable"});
  c.load = m.string("load", "");
  c.save = m.string("save", "");
  c.save_interval_s = m.number("save_interval_s", c.save_interval_s);
  if (c.save_interval_s < 0) m.fail("save_interval_s", "must be >= 0 (0: save only at a clean stop)");
  c.localize_only = m.choice("mode", std::string("slam"), {"slam", "localize"}) == "localize";
  c.start_without_unreadable = m.choice("on_unreadable", std::string("stop"), {"stop", "start_empty"}) == "start_empty";
  if (c.localize_only && c.load.empty()) m.fail("mode", "localize needs a map to load (map.load)");
  if (c.localize_only && !c.save.empty())
    m.fail("save", "a map only localized in is not changed: no save in mode localize");
}

void readRealtime(const YamlFields& rt, RealtimeConfig& r) {
  rt.allowOnly({"trigger_priority", "acquisition_priority", "processing_priority", "lock_memory", "cpus"});
  r.trigger_priority = static_cast<int>(rt.integer("trigger_priority", 0, 0, 99));
  r.acquisition_priority = static_cast<int>(rt.integer("acquisition_priority", 0, 0, 99));
  r.processing_priority = static_cast<int>(rt.integer("processing_priority", 0, 0, 99));
  r.lock_memory = rt.boolean("lock_memory", false);
  r.cpus = readIndexList(rt, "cpus", "CPU number", kMaxCpuNumber);
}

// The rig: the calibration file, or the dataset's own (possibly overridden by `calibration`), or the simulated one.
Rig datasetRig(const DaemonConfig& c) {
  DatasetOptions options;
  options.calibration_override = c.calibration;
  options.cameras = c.dataset.cameras;
  if (!c.calibration.empty()) {  // its own errors name its key, not the dataset's
    try {
      loadRigFromPath(c.calibration);
    } catch (const InputError& e) {
      throw InputError(c.file + ": calibration: " + e.what());
    }
  }
  try {
    return Dataset::open(c.dataset.path, options).rig();
  } catch (const InputError& e) {
    throw InputError(c.file + ": source.dataset.path: " + e.what());
  }
}

Rig simRig(const DaemonConfig& c, const YamlFields& top) {
  if (!c.calibration.empty())
    top.fail("calibration", "not used with source.type sim (the rig is source.sim.rig: a preset or a Kalibr file)");
  Rig full;
  try {
    full = sim::loadRig(c.sim.rig);
  } catch (const InputError& e) {
    throw InputError(c.file + ": source.sim.rig: " + e.what());
  }
  try {
    return c.sim.cameras.empty() ? full : full.subset(c.sim.cameras);
  } catch (const InputError& e) {
    throw InputError(c.file + ": source.sim.cameras: " + e.what());
  }
}

Rig aravisRig(const DaemonConfig& c, const YamlFields& top) {
  if (c.calibration.empty()) top.fail("calibration", "missing (required for source.type aravis)");
  Rig rig;
  try {
    rig = loadKalibrRig(c.calibration);
  } catch (const InputError& e) {
    throw InputError(c.file + ": calibration: " + e.what());
  }
  if (static_cast<int>(c.aravis.cameras.size()) != rig.size())
    top.child("source").fail("aravis", "lists " + std::to_string(c.aravis.cameras.size()) +
                                           " cameras but the calibration '" + c.calibration + "' has " +
                                           std::to_string(rig.size()));
  return rig;
}

Rig resolveRig(const DaemonConfig& c, const YamlFields& top) {
  switch (c.source_type) {
    case SourceType::Dataset: return datasetRig(c);
    case SourceType::Sim: return simRig(c, top);
    case SourceType::Aravis: break;
  }
  return aravisRig(c, top);
}

YAML::Node loadYaml(const std::string& yaml_text, const std::string& file) { return parseYamlText(yaml_text, file); }

}  // namespace

DaemonConfig parseDaemonConfig(const std::string& yaml_text, const std::string& file) {
  const YAML::Node root = loadYaml(yaml_text, file);
  DaemonConfig c;
  c.file = file;
  const YamlFields top(root, "", file);
  top.allowOnly({"log_level", "status_interval_s", "warmup_frames", "calibration", "source", "trigger", "assembly",
                 "capacities", "publish", "output", "map", "realtime", "slam"});
  c.log_level = top.choice("log_level", c.log_level, {"trace", "debug", "info", "warn", "error", "critical", "off"});
  c.status_interval_s = top.positiveNumber("status_interval_s", c.status_interval_s);
  c.warmup_frames = static_cast<double>(top.integer("warmup_frames", 50, 0, 1000000));
  c.calibration = resolvePath(file, top.string("calibration", ""));
  readSource(top, c);
  readTrigger(top.child("trigger"), c.trigger);
  if (c.source_type != SourceType::Aravis && c.trigger.mode == TriggerMode::Gpio)
    top.fail("trigger", std::string("mode gpio needs cameras (source.type aravis); a ") + configName(c.source_type) +
                            " source runs free_running or software");
  readAssembly(top.child("assembly"), c.assembly);
  readCapacities(top.child("capacities"), c.capacities);
  readPublish(top.child("publish"), c.publish);
  readOutput(top.child("output"), c.output);
  readMap(top.child("map"), c.map);
  readRealtime(top.child("realtime"), c.realtime);
  c.slam = root["slam"] ? root["slam"] : YAML::Node(YAML::NodeType::Map);
  c.rig = resolveRig(c, top);
  if (c.rig.size() > static_cast<int>(c.capacities.max_cameras))
    top.child("capacities")
        .fail("max_cameras", "is " + std::to_string(c.capacities.max_cameras) + " but the rig has " +
                                 std::to_string(c.rig.size()) + " cameras");
  validatePipelineConfig(c.slam, file, c.rig);
  return c;
}

bool exitsAtEnd(const DaemonConfig& c) {
  return (c.source_type == SourceType::Dataset && c.dataset.at_end == AtEnd::Exit) ||
         (c.source_type == SourceType::Sim && c.sim.at_end == AtEnd::Exit);
}

SourceContext sourceContext(const DaemonConfig& c) {
  SourceContext s;
  s.file = c.file;
  s.rig = c.rig;
  s.trigger = c.trigger;
  s.acquisition_priority = c.realtime.acquisition_priority;
  s.calibration = c.calibration;
  return s;
}

DaemonConfig loadDaemonConfig(const std::string& path) {
  return parseDaemonConfig(readTextFile(path, kMaxConfigFileBytes), path);
}

}  // namespace mcslam::platform
