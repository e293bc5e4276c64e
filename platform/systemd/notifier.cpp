#include "systemd/notifier.hpp"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstddef>
#include <cstdlib>
#include <cstring>

namespace mcslam::platform {

SystemdNotifier::SystemdNotifier() {
  const char* path = std::getenv("NOTIFY_SOCKET");
  if (path && path[0] != '\0' && (path[0] == '/' || path[0] == '@')) {
    sockaddr_un addr{};
    const std::size_t len = std::strlen(path);
    if (len < sizeof(addr.sun_path)) {
      addr.sun_family = AF_UNIX;
      std::memcpy(addr.sun_path, path, len);
      if (path[0] == '@') addr.sun_path[0] = '\0';  // abstract namespace
      address_length_ = static_cast<unsigned>(offsetof(sockaddr_un, sun_path) + len);
      static_assert(sizeof(sockaddr_un) <= sizeof(address_));
      std::memcpy(address_, &addr, sizeof(addr));
      fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    }
  }
  const char* usec = std::getenv("WATCHDOG_USEC");
  const char* pid = std::getenv("WATCHDOG_PID");
  if (usec && (!pid || std::atol(pid) == static_cast<long>(::getpid()))) watchdog_us_ = std::atoll(usec);
}

SystemdNotifier::~SystemdNotifier() {
  if (fd_ >= 0) ::close(fd_);
}

bool SystemdNotifier::send(const char* message) {
  if (fd_ < 0) return false;
  const ssize_t n = ::sendto(fd_, message, std::strlen(message), MSG_NOSIGNAL,
                             reinterpret_cast<const sockaddr*>(address_), address_length_);
  return n >= 0;
}

bool SystemdNotifier::status(const char* text) {
  char buf[512] = "STATUS=";
  std::size_t n = 7;
  for (const char* p = text; *p && n + 1 < sizeof(buf); ++p) buf[n++] = (*p == '\n') ? ' ' : *p;
  buf[n] = '\0';
  return send(buf);
}

}  // namespace mcslam::platform
