#include "daemon/daemon_config.hpp"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "daemon/yaml_fields.hpp"
#include "mcslam/calib/calibration_io.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/dataset/dataset.hpp"
#include "mcslam/pipeline/pipeline_factory.hpp"
#include "mcslam/sim/rig_presets.hpp"
#include "mcslam/sim/world.hpp"
#include "udp/udp_pose_sender.hpp"

namespace mcslam::platform {

namespace {

std::string resolvePath(const std::string& file, const std::string& path) {
  if (path.empty() || std::filesystem::path(path).is_absolute()) return path;
  const auto dir = std::filesystem::path(file).parent_path();
  return (dir.empty() ? std::filesystem::path(path) : dir / path).lexically_normal().string();
}

std::vector<int> readCameraList(const YamlFields& f) {
  std::vector<int> cameras;
  if (!f.has("cameras")) return cameras;
  const YAML::Node n = f.node("cameras");
  if (!n.IsSequence()) f.fail("cameras", "expected a list of calibration indices");
  for (std::size_t i = 0; i < n.size(); ++i) {
    int v = 0;
    if (!n[i].IsScalar() || !YAML::convert<int>::decode(n[i], v) || v < 0)
      f.fail("cameras", "item " + std::to_string(i) + " must be a camera index >= 0");
    cameras.push_back(v);
  }
  return cameras;
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
  s.pace = f.choice("pace", s.pace, {"fastest", "realtime"});
  s.at_end = f.choice("at_end", s.at_end, {"exit", "loop", "idle"});
  s.anti_aliasing = f.boolean("anti_aliasing", s.anti_aliasing);
  s.render_threads = static_cast<int>(f.integer("render_threads", s.render_threads, 0, 256));
  s.cameras = readCameraList(f);
}

void readDataset(const YamlFields& f, DatasetSourceConfig& d) {
  f.allowOnly({"path", "rate", "speed", "at_end", "preload", "max_preload_frames", "cameras"});
  d.path = resolvePath(f.file(), f.requiredString("path"));
  d.rate = f.choice("rate", d.rate, {"recorded", "fastest"});
  d.speed = f.positiveNumber("speed", d.speed);
  d.at_end = f.choice("at_end", d.at_end, {"exit", "loop", "idle"});
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
  t.mode = f.choice("mode", t.mode, {"free_running", "software", "gpio"});
  t.rate_hz = f.positiveNumber("rate_hz", t.rate_hz);
  if (t.rate_hz > 1000) f.fail("rate_hz", "at most 1000 Hz, got " + std::to_string(t.rate_hz));
  t.gpio_chip = f.string("gpio_chip", t.gpio_chip);
  t.gpio_line = static_cast<int>(f.integer("gpio_line", t.gpio_line, -1, 4095));
  t.pulse_us = static_cast<int>(f.integer("pulse_us", t.pulse_us, 1, 100000));
  t.active_low = f.boolean("active_low", t.active_low);
  if (t.mode == "gpio") {
    if (t.gpio_chip.empty()) f.fail("gpio_chip", "required when trigger.mode is gpio");
    if (t.gpio_line < 0) f.fail("gpio_line", "required when trigger.mode is gpio");
    if (t.pulse_us * 1e-6 >= 1.0 / t.rate_hz) f.fail("pulse_us", "the pulse must be shorter than the trigger period");
  }
}

}  // namespace

DaemonConfig parseDaemonConfig(const std::string& yaml_text, const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw InputError(file + ": not valid YAML: " + e.what());
  }
  DaemonConfig c;
  c.file = file;
  const YamlFields top(root, "", file);
  top.allowOnly({"log_level", "status_interval_s", "warmup_frames", "calibration", "source", "trigger", "assembly",
                 "capacities", "publish", "output", "realtime", "slam"});
  c.log_level = top.choice("log_level", c.log_level, {"trace", "debug", "info", "warn", "error", "critical", "off"});
  c.status_interval_s = top.positiveNumber("status_interval_s", c.status_interval_s);
  c.warmup_frames = static_cast<double>(top.integer("warmup_frames", 50, 0, 1000000));
  c.calibration = resolvePath(file, top.string("calibration", ""));

  const YamlFields source = top.child("source");
  source.allowOnly({"type", "dataset", "aravis", "sim"});
  if (!source.has("type")) source.fail("type", "missing (required): dataset, aravis or sim");
  c.source_type = source.choice("type", "", {"dataset", "aravis", "sim"});
  for (const char* other : {"dataset", "aravis", "sim"})
    if (c.source_type != other && source.has(other)) source.fail(other, "given but source.type is " + c.source_type);
  if (c.source_type == "dataset") readDataset(source.child("dataset"), c.dataset);
  else if (c.source_type == "aravis") readAravis(source.child("aravis"), c.aravis);
  else readSim(source.child("sim"), c.sim);

  readTrigger(top.child("trigger"), c.trigger);
  if (c.source_type != "aravis" && c.trigger.mode == "gpio")
    top.fail("trigger", "mode gpio needs cameras (source.type aravis); a " + c.source_type +
                            " source runs free_running or software");

  const YamlFields assembly = top.child("assembly");
  assembly.allowOnly({"match_by", "tolerance_ms", "timeout_ms"});
  c.assembly.match_by = assembly.choice("match_by", c.assembly.match_by, {"trigger_count", "timestamp"});
  c.assembly.tolerance_ms = assembly.positiveNumber("tolerance_ms", c.assembly.tolerance_ms);
  c.assembly.timeout_ms = assembly.positiveNumber("timeout_ms", c.assembly.timeout_ms);

  const YamlFields cap = top.child("capacities");
  cap.allowOnly({"max_cameras", "camera_ring_slots", "pending_rig_frames", "rig_ring_slots", "pose_ring_slots"});
  c.capacities.max_cameras = cap.capacity("max_cameras", c.capacities.max_cameras, 64);
  c.capacities.camera_ring_slots = cap.capacity("camera_ring_slots", c.capacities.camera_ring_slots, 1024);
  c.capacities.pending_rig_frames = cap.capacity("pending_rig_frames", c.capacities.pending_rig_frames, 64);
  c.capacities.rig_ring_slots = cap.capacity("rig_ring_slots", c.capacities.rig_ring_slots, 1024);
  c.capacities.pose_ring_slots = cap.capacity("pose_ring_slots", c.capacities.pose_ring_slots, 65536);

  const YamlFields pub = top.child("publish");
  pub.allowOnly({"shm", "udp"});
  const YamlFields shm = pub.child("shm");
  shm.allowOnly({"enabled", "name", "mode", "ring_length"});
  c.publish.shm_enabled = shm.boolean("enabled", c.publish.shm_enabled);
  c.publish.shm_name = shm.string("name", c.publish.shm_name);
  if (c.publish.shm_name.size() < 2 || c.publish.shm_name[0] != '/' ||
      c.publish.shm_name.find('/', 1) != std::string::npos)
    shm.fail("name", "'" + c.publish.shm_name + "' must be '/' followed by a name without '/'");
  c.publish.shm_mode = shm.permissions("mode", c.publish.shm_mode);
  c.publish.shm_ring_length = shm.capacity("ring_length", c.publish.shm_ring_length, 1u << 20);
  const YamlFields udp = pub.child("udp");
  udp.allowOnly({"destinations"});
  c.publish.udp_destinations = udp.stringList("destinations");
  for (const auto& d : c.publish.udp_destinations) resolveUdpDestination(d, file + ": " + udp.keyName("destinations"));

  const YamlFields out = top.child("output");
  out.allowOnly({"directory", "trajectory", "extrinsics"});
  c.output.directory = resolvePath(file, out.string("directory", ""));
  c.output.trajectory = out.string("trajectory", c.output.trajectory);
  c.output.extrinsics = out.string("extrinsics", c.output.extrinsics);
  if (c.output.trajectory.empty()) out.fail("trajectory", "must not be empty");

  const YamlFields rt = top.child("realtime");
  rt.allowOnly({"trigger_priority", "acquisition_priority", "processing_priority", "lock_memory"});
  c.realtime.trigger_priority = static_cast<int>(rt.integer("trigger_priority", 0, 0, 99));
  c.realtime.acquisition_priority = static_cast<int>(rt.integer("acquisition_priority", 0, 0, 99));
  c.realtime.processing_priority = static_cast<int>(rt.integer("processing_priority", 0, 0, 99));
  c.realtime.lock_memory = rt.boolean("lock_memory", false);

  c.slam = root["slam"] ? root["slam"] : YAML::Node(YAML::NodeType::Map);

  // The rig: the calibration file, or the dataset's own (possibly overridden by `calibration`).
  if (c.source_type == "dataset") {
    DatasetOptions options;
    options.calibration_override = c.calibration;
    options.cameras = c.dataset.cameras;
    try {
      c.rig = Dataset::open(c.dataset.path, options).rig();
    } catch (const InputError& e) {
      throw InputError(file + ": source.dataset.path: " + e.what());
    }
  } else if (c.source_type == "sim") {
    if (!c.calibration.empty())
      top.fail("calibration", "not used with source.type sim (the rig is source.sim.rig: a preset or a Kalibr file)");
    Rig full;
    try {
      full = sim::loadRig(c.sim.rig);
    } catch (const InputError& e) {
      throw InputError(file + ": source.sim.rig: " + e.what());
    }
    try {
      c.rig = c.sim.cameras.empty() ? full : full.subset(c.sim.cameras);
    } catch (const InputError& e) {
      throw InputError(file + ": source.sim.cameras: " + e.what());
    }
  } else {
    if (c.calibration.empty()) top.fail("calibration", "missing (required for source.type aravis)");
    try {
      c.rig = loadKalibrRig(c.calibration);
    } catch (const InputError& e) {
      throw InputError(file + ": calibration: " + e.what());
    }
    if (static_cast<int>(c.aravis.cameras.size()) != c.rig.size())
      source.fail("aravis", "lists " + std::to_string(c.aravis.cameras.size()) + " cameras but the calibration '" +
                                c.calibration + "' has " + std::to_string(c.rig.size()));
  }
  if (c.rig.size() > static_cast<int>(c.capacities.max_cameras))
    cap.fail("max_cameras", "is " + std::to_string(c.capacities.max_cameras) + " but the rig has " +
                                std::to_string(c.rig.size()) + " cameras");
  validatePipelineConfig(c.slam, file, c.rig);
  return c;
}

bool exitsAtEnd(const DaemonConfig& c) {
  return (c.source_type == "dataset" && c.dataset.at_end == "exit") || (c.source_type == "sim" && c.sim.at_end == "exit");
}

DaemonConfig loadDaemonConfig(const std::string& path) {
  return parseDaemonConfig(readTextFile(path), path);
}

std::string effectiveDaemonConfig(const DaemonConfig& c) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "log_level" << YAML::Value << c.log_level;
  e << YAML::Key << "status_interval_s" << YAML::Value << c.status_interval_s;
  e << YAML::Key << "warmup_frames" << YAML::Value << static_cast<long long>(c.warmup_frames);
  e << YAML::Key << "calibration" << YAML::Value << c.calibration;
  e << YAML::Key << "source" << YAML::Value << YAML::BeginMap << YAML::Key << "type" << YAML::Value << c.source_type;
  if (c.source_type == "dataset") {
    const auto& d = c.dataset;
    e << YAML::Key << "dataset" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "path" << YAML::Value << d.path << YAML::Key << "rate" << YAML::Value << d.rate;
    e << YAML::Key << "speed" << YAML::Value << d.speed << YAML::Key << "at_end" << YAML::Value << d.at_end;
    e << YAML::Key << "preload" << YAML::Value << d.preload;
    e << YAML::Key << "max_preload_frames" << YAML::Value << d.max_preload_frames;
    e << YAML::Key << "cameras" << YAML::Value << YAML::Flow << d.cameras;
    e << YAML::EndMap;
  } else if (c.source_type == "sim") {
    const auto& m = c.sim;
    e << YAML::Key << "sim" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "rig" << YAML::Value << m.rig << YAML::Key << "world" << YAML::Value << m.world;
    e << YAML::Key << "trajectory" << YAML::Value << m.trajectory << YAML::Key << "rate_hz" << YAML::Value << m.rate_hz;
    e << YAML::Key << "frames" << YAML::Value << m.frames << YAML::Key << "seed" << YAML::Value << m.seed;
    e << YAML::Key << "pace" << YAML::Value << m.pace << YAML::Key << "at_end" << YAML::Value << m.at_end;
    e << YAML::Key << "anti_aliasing" << YAML::Value << m.anti_aliasing;
    e << YAML::Key << "render_threads" << YAML::Value << m.render_threads;
    e << YAML::Key << "cameras" << YAML::Value << YAML::Flow << m.cameras;
    e << YAML::EndMap;
  } else {
    const auto& a = c.aravis;
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
  e << YAML::EndMap;
  const auto& t = c.trigger;
  e << YAML::Key << "trigger" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "mode" << YAML::Value << t.mode << YAML::Key << "rate_hz" << YAML::Value << t.rate_hz;
  e << YAML::Key << "gpio_chip" << YAML::Value << t.gpio_chip << YAML::Key << "gpio_line" << YAML::Value << t.gpio_line;
  e << YAML::Key << "pulse_us" << YAML::Value << t.pulse_us << YAML::Key << "active_low" << YAML::Value << t.active_low;
  e << YAML::EndMap;
  e << YAML::Key << "assembly" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "match_by" << YAML::Value << c.assembly.match_by;
  e << YAML::Key << "tolerance_ms" << YAML::Value << c.assembly.tolerance_ms;
  e << YAML::Key << "timeout_ms" << YAML::Value << c.assembly.timeout_ms << YAML::EndMap;
  const auto& k = c.capacities;
  e << YAML::Key << "capacities" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "max_cameras" << YAML::Value << k.max_cameras;
  e << YAML::Key << "camera_ring_slots" << YAML::Value << k.camera_ring_slots;
  e << YAML::Key << "pending_rig_frames" << YAML::Value << k.pending_rig_frames;
  e << YAML::Key << "rig_ring_slots" << YAML::Value << k.rig_ring_slots;
  e << YAML::Key << "pose_ring_slots" << YAML::Value << k.pose_ring_slots << YAML::EndMap;
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
  const auto& r = c.realtime;
  e << YAML::Key << "realtime" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "trigger_priority" << YAML::Value << r.trigger_priority;
  e << YAML::Key << "acquisition_priority" << YAML::Value << r.acquisition_priority;
  e << YAML::Key << "processing_priority" << YAML::Value << r.processing_priority;
  e << YAML::Key << "lock_memory" << YAML::Value << r.lock_memory << YAML::EndMap;
  e << YAML::EndMap;
  std::ostringstream os;
  os << e.c_str() << "\n";
  os << "# rig: " << c.rig.size() << " camera(s)\n";
  os << effectivePipelineConfig(c.slam, c.file, c.rig);
  return os.str();
}

}  // namespace mcslam::platform
