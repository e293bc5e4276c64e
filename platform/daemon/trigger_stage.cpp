#include "daemon/trigger_stage.hpp"

#include "gpio/gpiod_line.hpp"
#include "mcslam/core/error.hpp"

namespace mcslam::platform {

TriggerStage::TriggerStage(const TriggerConfig& t, int priority, FrameSource& source, const std::string& file) {
  switch (t.mode) {
    case TriggerMode::Gpio:
      gpio_line_ = std::make_unique<GpiodLine>(t.gpio_chip, t.gpio_line, t.active_low);
      pulse_ = std::make_unique<PulseTrigger>(*gpio_line_, static_cast<int64_t>(t.pulse_us) * 1000);
      thread_ = std::make_unique<TriggerThread>(*pulse_, log_, t.rate_hz, priority);
      break;
    case TriggerMode::Software: {
      TriggerOutput* out = source.softwareTrigger();
      if (!out) throw InputError(file + ": trigger.mode: this source has no software trigger");
      thread_ = std::make_unique<TriggerThread>(*out, log_, t.rate_hz, priority);
      break;
    }
    case TriggerMode::FreeRunning: break;
  }
}

void TriggerStage::start() {
  if (thread_) thread_->start();
}

void TriggerStage::stop() {
  if (thread_) thread_->stop();
}

}  // namespace mcslam::platform
