#pragma once
// The sd_notify protocol without libsystemd: one datagram "KEY=value\n..." to the AF_UNIX socket named
// by $NOTIFY_SOCKET (a path, or '@' for the abstract namespace). Without the variable (not started by
// systemd) every call is a no-op. Messages are formatted into a fixed buffer: no allocation.
#include <cstdint>

namespace mcslam::platform {

class SystemdNotifier {
 public:
  // Reads $NOTIFY_SOCKET and $WATCHDOG_USEC (honouring $WATCHDOG_PID).
  SystemdNotifier();
  ~SystemdNotifier();
  SystemdNotifier(const SystemdNotifier&) = delete;
  SystemdNotifier& operator=(const SystemdNotifier&) = delete;

  bool enabled() const { return fd_ >= 0; }
  // Interval systemd expects keep-alives within (0 = no watchdog).
  int64_t watchdogIntervalUs() const { return watchdog_us_; }

  bool ready() { return send("READY=1"); }
  bool watchdog() { return send("WATCHDOG=1"); }
  bool stopping() { return send("STOPPING=1"); }
  // STATUS=<text> (newlines replaced).
  bool status(const char* text);
  // Any message; returns false when not sent.
  bool send(const char* message);

 private:
  int fd_ = -1;
  char address_[128] = {};
  unsigned address_length_ = 0;
  int64_t watchdog_us_ = 0;
};

}  // namespace mcslam::platform
