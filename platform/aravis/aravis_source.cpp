#include "aravis/aravis_source.hpp"

#include <arv.h>
#include <time.h>

#include <spdlog/spdlog.h>

#include "mcslam/core/error.hpp"
#include "realtime/scheduling.hpp"

namespace mcslam::platform {

namespace {
constexpr int64_t kMs = 1000000;

// Throws when err is set; clears it.
void check(GError*& err, const std::string& key, const std::string& what) {
  if (!err) return;
  const std::string message = err->message ? err->message : "unknown error";
  g_clear_error(&err);
  throw InputError(key + ": " + what + ": " + message);
}

// Logs and clears a non-fatal error.
void warnIf(GError*& err, const std::string& key, const std::string& what) {
  if (!err) return;
  spdlog::warn("{}: {}: {}", key, what, err->message ? err->message : "unknown error");
  g_clear_error(&err);
}

int64_t realtimeNowNs() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}
}  // namespace

AravisSource::AravisSource(const AravisSourceConfig& config, const SourceContext& context)
    : config_(config), context_(context), software_(context.trigger.mode == TriggerMode::Software) {
  for (std::size_t i = 0; i < config.cameras.size(); ++i) {
    auto cam = std::make_unique<Camera>();
    cam->index = static_cast<int>(i);
    cam->cfg = config.cameras[i];
    cam->key = context.file + ": source.aravis.cameras[" + std::to_string(i) + "]";
    cam->layout = pixelLayoutFromName(cam->cfg.pixel_format);
    cam->width = context.rig.model(static_cast<int>(i)).width();
    cam->height = context.rig.model(static_cast<int>(i)).height();
    try {
      open(*cam);
    } catch (...) {
      // Release what is open (a GigE camera keeps its control privilege for a previous owner until
      // it is closed properly), then report.
      close(*cam);
      for (auto& opened : cameras_) close(*opened);
      throw;
    }
    cameras_.push_back(std::move(cam));
  }
}

AravisSource::~AravisSource() {
  stop();
  for (auto& cam : cameras_) close(*cam);
}

void AravisSource::open(Camera& cam) {
  GError* err = nullptr;
  const std::string& key = cam.key;
  cam.camera = arv_camera_new(cam.cfg.id.c_str(), &err);
  if (!cam.camera) {
    const std::string why = err && err->message ? err->message : "not found";
    g_clear_error(&err);
    throw InputError(key + ".id: cannot open camera '" + cam.cfg.id + "': " + why);
  }
  arv_camera_set_acquisition_mode(cam.camera, ARV_ACQUISITION_MODE_CONTINUOUS, &err);
  warnIf(err, key, "acquisition mode");
  arv_camera_set_pixel_format_from_string(cam.camera, cam.cfg.pixel_format.c_str(), &err);
  check(err, key + ".pixel_format", "camera '" + cam.cfg.id + "' refuses " + cam.cfg.pixel_format);

  // The image size must be the calibrated one; try to set it when it is not.
  gint x = 0, y = 0, w = 0, h = 0;
  arv_camera_get_region(cam.camera, &x, &y, &w, &h, &err);
  check(err, key, "reading the image size");
  if (w != cam.width || h != cam.height) {
    arv_camera_set_region(cam.camera, 0, 0, cam.width, cam.height, &err);
    g_clear_error(&err);
    arv_camera_get_region(cam.camera, &x, &y, &w, &h, &err);
    check(err, key, "reading the image size");
    if (w != cam.width || h != cam.height)
      throw InputError(key + ": camera '" + cam.cfg.id + "' delivers " + std::to_string(w) + "x" + std::to_string(h) +
                       " but the calibration says " + std::to_string(cam.width) + "x" + std::to_string(cam.height));
  }
  if (cam.cfg.exposure_us > 0) {
    arv_camera_set_exposure_time_auto(cam.camera, ARV_AUTO_OFF, &err);
    g_clear_error(&err);  // cameras without auto exposure
    arv_camera_set_exposure_time(cam.camera, cam.cfg.exposure_us, &err);
    check(err, key + ".exposure_us", "camera '" + cam.cfg.id + "' refuses " + std::to_string(cam.cfg.exposure_us));
  }
  if (cam.cfg.gain_db >= 0) {
    arv_camera_set_gain_auto(cam.camera, ARV_AUTO_OFF, &err);
    g_clear_error(&err);
    arv_camera_set_gain(cam.camera, cam.cfg.gain_db, &err);
    check(err, key + ".gain_db", "camera '" + cam.cfg.id + "' refuses " + std::to_string(cam.cfg.gain_db));
  }
  const TriggerMode mode = context_.trigger.mode;
  if (mode == TriggerMode::Gpio) {
    arv_camera_set_trigger(cam.camera, cam.cfg.trigger_line.c_str(), &err);
    check(err, key + ".trigger_line", "camera '" + cam.cfg.id + "' cannot trigger on " + cam.cfg.trigger_line);
  } else if (mode == TriggerMode::Software) {
    arv_camera_set_trigger(cam.camera, "Software", &err);
    check(err, context_.file + ": trigger.mode", "camera '" + cam.cfg.id + "' has no software trigger");
  } else {
    arv_camera_clear_triggers(cam.camera, &err);
    warnIf(err, key, "free-running");
    arv_camera_set_frame_rate(cam.camera, context_.trigger.rate_hz, &err);
    warnIf(err, key, "frame rate");
  }
  if (arv_camera_is_gv_device(cam.camera)) {
    if (config_.packet_size > 0)
      arv_camera_gv_set_packet_size(cam.camera, config_.packet_size, &err);
    else
      arv_camera_gv_auto_packet_size(cam.camera, &err);
    warnIf(err, key, "packet size");
  }
  cam.stream = arv_camera_create_stream(cam.camera, nullptr, nullptr, &err);
  if (!cam.stream) {
    const std::string why = err && err->message ? err->message : "unknown error";
    g_clear_error(&err);
    throw InputError(key + ": cannot open a stream from camera '" + cam.cfg.id + "': " + why);
  }
  const guint payload = arv_camera_get_payload(cam.camera, &err);
  check(err, key, "payload size");
  for (uint32_t i = 0; i < config_.stream_buffers; ++i)  // allocated once, pushed once
    arv_stream_push_buffer(cam.stream, arv_buffer_new(payload, nullptr));
}

void AravisSource::close(Camera& cam) {
  if (cam.camera) {
    GError* err = nullptr;
    arv_camera_stop_acquisition(cam.camera, &err);
    g_clear_error(&err);
  }
  if (cam.stream) g_object_unref(cam.stream);
  if (cam.camera) g_object_unref(cam.camera);
  cam.stream = nullptr;
  cam.camera = nullptr;
}

void AravisSource::start(const SourceLinks& links) {
  rings_ = links.rings;
  triggers_ = links.triggers;
  warm_up_ = links.warm_up;
  stop_ = false;
  for (auto& cam : cameras_) {
    if (!cam->camera) open(*cam);  // started again after a stop
    GError* err = nullptr;
    arv_camera_start_acquisition(cam->camera, &err);
    warnIf(err, cam->key, "start acquisition");
    cam->last_frame_mono = monotonicNowNs();
    Camera* c = cam.get();
    cam->thread = std::thread([this, c] { acquire(*c); });
  }
}

void AravisSource::stop() {
  stop_ = true;
  for (auto& cam : cameras_)
    if (cam->thread.joinable()) cam->thread.join();
  // Released at once, not with the object: a GigE camera keeps its control privilege until it is closed, and a
  // daemon that ends its process without destroying its objects (a pipeline stuck at the stop) must leave it free
  // for the daemon systemd starts next.
  for (auto& cam : cameras_) close(*cam);
}

bool AravisSource::fire(uint64_t) {
  bool ok = true;
  for (auto& cam : cameras_) {
    std::unique_lock<std::mutex> lock(cam->handle_mutex, std::try_to_lock);  // never wait on a reopen
    if (!lock.owns_lock() || cam->lost.load(std::memory_order_relaxed) || !cam->camera) {
      ok = false;
      continue;
    }
    GError* err = nullptr;
    arv_camera_software_trigger(cam->camera, &err);
    if (err) {
      ok = false;
      g_clear_error(&err);
    }
  }
  return ok;
}

bool AravisSource::tryReopen(Camera& cam) {
  std::lock_guard<std::mutex> lock(cam.handle_mutex);
  close(cam);
  try {
    open(cam);
  } catch (const InputError& e) {
    close(cam);
    spdlog::debug("{}", e.what());
    return false;
  }
  GError* err = nullptr;
  arv_camera_start_acquisition(cam.camera, &err);
  if (err) {
    g_clear_error(&err);
    close(cam);
    return false;
  }
  return true;
}

void AravisSource::acquire(Camera& cam) {
  char name[16];
  std::snprintf(name, sizeof(name), "mcslam-cam%d", cam.index);
  nameThisThread(name);
  if (const auto why = setRealtimePriority(context_.acquisition_priority); !why.empty())
    spdlog::warn("{} thread: {}", name, why);
  const int64_t timeout_ns = static_cast<int64_t>(config_.frame_timeout_ms * kMs);
  const bool triggered = context_.trigger.mode != TriggerMode::FreeRunning;
  int64_t last_reopen = 0;
  uint64_t bad_logged = 0;
  while (!stop_.load(std::memory_order_relaxed)) {
    const int64_t now = monotonicNowNs();
    if (cam.lost.load(std::memory_order_relaxed)) {
      if (now - last_reopen > 1000 * kMs) {
        last_reopen = now;
        if (tryReopen(cam)) {
          cam.lost = false;
          cam.last_frame_mono = monotonicNowNs();
          spdlog::info("{}: camera '{}' is back", cam.key, cam.cfg.id);
        }
      }
      timespec ts{0, 100 * kMs};
      clock_nanosleep(CLOCK_MONOTONIC, 0, &ts, nullptr);
      continue;
    }
    ArvBuffer* buffer = arv_stream_timeout_pop_buffer(cam.stream, 100000);
    if (!buffer) {
      if (monotonicNowNs() - cam.last_frame_mono > timeout_ns) {
        cam.lost = true;
        counters_.lost_events.fetch_add(1, std::memory_order_relaxed);
        spdlog::error("{}: camera '{}' delivered nothing for {} ms: lost; reopening", cam.key, cam.cfg.id,
                      config_.frame_timeout_ms);
      }
      continue;
    }
    const int64_t arrival = monotonicNowNs();
    cam.last_frame_mono = arrival;
    const ArvBufferStatus status = arv_buffer_get_status(buffer);
    size_t size = 0;
    const auto* data = static_cast<const uint8_t*>(arv_buffer_get_data(buffer, &size));
    bool good = status == ARV_BUFFER_STATUS_SUCCESS && data;
    if (good) {
      CameraFrame& slot = rings_->slot(cam.index);
      good = convertToGrey(cam.layout, data, size, arv_buffer_get_image_width(buffer),
                           arv_buffer_get_image_height(buffer), slot.image);
      if (good) {
        const int64_t system_ns = static_cast<int64_t>(arv_buffer_get_system_timestamp(buffer));
        slot.capture_ns = system_ns > 0 ? system_ns : realtimeNowNs();
        // A triggered frame belongs to the newest trigger fired before it arrived: unlike counting
        // frame IDs, this stays right after a camera missed a pulse. Free-running: the frame count.
        uint64_t index = cam.frames;
        int64_t fired = 0;
        if (triggered && triggers_->latestAtOrBefore(arrival, index, fired)) {
          slot.trigger_index = index;
          slot.trigger_mono_ns = fired;
        } else {
          slot.trigger_index = cam.frames;
          slot.trigger_mono_ns = arrival;
        }
      }
    }
    arv_stream_push_buffer(cam.stream, buffer);  // back to the stream at once
    if (good) {
      rings_->publish(cam.index);
      ++cam.frames;
      counters_.frames.fetch_add(1, std::memory_order_relaxed);
    } else if (counters_.bad_frames.fetch_add(1, std::memory_order_relaxed); bad_logged++ < 20) {
      spdlog::warn("{}: bad frame (buffer status {}, {} bytes)", cam.key, static_cast<int>(status), size);
    }
    cam.meter.note(warm_up_->warm());
  }
}

void AravisSource::health(char* out, std::size_t size) const {
  int n = std::snprintf(out, size, "ok");
  bool any = false;
  for (const auto& cam : cameras_) {
    if (!cam->lost.load(std::memory_order_relaxed)) continue;
    if (!any) n = 0;
    any = true;
    if (n >= 0 && static_cast<std::size_t>(n) < size)
      n += std::snprintf(out + n, size - n, "%scam%d lost", n ? ", " : "", cam->index);
  }
}

uint64_t AravisSource::allocationsSinceWarmup() const {
  uint64_t n = 0;
  for (const auto& cam : cameras_) n += cam->meter.since();
  return n;
}

}  // namespace mcslam::platform
