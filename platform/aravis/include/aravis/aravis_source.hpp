#pragma once
// GenICam cameras through Aravis 0.8 (GigE Vision and USB3 Vision). Per camera: opened by serial
// number, device ID or IP address; exposure, gain and pixel format from the config; trigger from the
// config (hardware line, software, or free-running); stream buffers allocated once and pushed once,
// each returned to the stream right after its image is converted. One acquisition thread per camera.
// A camera that stops delivering is reported lost and reopened until it comes back.
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "aravis/aravis_config.hpp"
#include "aravis/pixel_convert.hpp"
#include "realtime/alloc_meter.hpp"
#include "sources/frame_source.hpp"
#include "sources/source_config.hpp"

typedef struct _ArvCamera ArvCamera;
typedef struct _ArvStream ArvStream;

namespace mcslam::platform {

class AravisSource final : public FrameSource, private TriggerOutput {
 public:
  // Opens and configures every camera. Throws InputError naming source.aravis.cameras[i] when a
  // camera is unreachable or refuses a setting.
  AravisSource(const AravisSourceConfig& config, const SourceContext& context);
  ~AravisSource() override;

  void start(const SourceLinks& links) override;
  void stop() override;
  TriggerOutput* softwareTrigger() override { return software_ ? this : nullptr; }
  void health(char* out, std::size_t size) const override;
  uint64_t allocationsSinceWarmup() const override;

 private:
  struct Camera {
    int index = 0;
    AravisCameraConfig cfg;
    std::string key;  // "source.aravis.cameras[i]"
    PixelLayout layout = PixelLayout::Mono8;
    int width = 0, height = 0;
    std::mutex handle_mutex;  // guards camera/stream against the trigger thread while reopening
    ArvCamera* camera = nullptr;
    ArvStream* stream = nullptr;
    std::atomic<bool> lost{false};
    uint64_t frames = 0;
    int64_t last_frame_mono = 0;
    ThreadAllocMeter meter;
    std::thread thread;
  };

  bool fire(uint64_t index) override;
  void open(Camera& cam);  // throws InputError
  void close(Camera& cam);
  void acquire(Camera& cam);
  bool tryReopen(Camera& cam);

  AravisSourceConfig config_;
  SourceContext context_;
  bool software_;
  std::vector<std::unique_ptr<Camera>> cameras_;
  CameraRings* rings_ = nullptr;
  const TriggerLog* triggers_ = nullptr;
  const WarmUp* warm_up_ = nullptr;
  std::atomic<bool> stop_{false};
};

}  // namespace mcslam::platform
