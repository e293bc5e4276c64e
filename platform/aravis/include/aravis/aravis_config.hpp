#pragma once
// The `source.aravis:` section of mcslamd's configuration: GenICam cameras in calibration order.
#include <cstdint>
#include <string>
#include <vector>

namespace mcslam::platform {

struct AravisCameraConfig {
  std::string id;                      // serial number, device ID or IP address
  double exposure_us = 0;              // 0 = leave as configured on the camera
  double gain_db = -1;                 // < 0 = leave
  std::string pixel_format = "Mono8";  // Mono8 | BayerRG8 | BayerGR8 | BayerGB8 | BayerBG8 (the GenICam name)
  std::string trigger_line = "Line1";  // camera input wired to the GPIO pulse (trigger.mode gpio)
};

struct AravisSourceConfig {
  std::vector<AravisCameraConfig> cameras;  // in calibration order
  uint32_t stream_buffers = 8;
  int packet_size = 0;             // GigE packet size, 0 = negotiate
  double frame_timeout_ms = 1000;  // no frame for this long: the camera counts as lost and is reopened
};

}  // namespace mcslam::platform
