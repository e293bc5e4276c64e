#include "udp/udp_pose_sender.hpp"

#include <netdb.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "mcslam/core/error.hpp"

namespace mcslam::platform {

UdpDestination resolveUdpDestination(const std::string& text, const std::string& key) {
  std::string host, port;
  if (!text.empty() && text[0] == '[') {
    const auto close = text.find(']');
    if (close == std::string::npos || close + 1 >= text.size() || text[close + 1] != ':')
      throw InputError(key + ": '" + text + "' is not [ipv6]:port");
    host = text.substr(1, close - 1);
    port = text.substr(close + 2);
  } else {
    const auto colon = text.rfind(':');
    if (colon == std::string::npos || colon == 0) throw InputError(key + ": '" + text + "' is not host:port");
    host = text.substr(0, colon);
    port = text.substr(colon + 1);
  }
  char* end = nullptr;
  const long p = std::strtol(port.c_str(), &end, 10);
  if (port.empty() || *end != '\0' || p < 1 || p > 65535)
    throw InputError(key + ": '" + text + "' has no valid port (1..65535)");
  addrinfo hints{};
  hints.ai_socktype = SOCK_DGRAM;
  hints.ai_family = AF_UNSPEC;
  addrinfo* res = nullptr;
  const int rc = ::getaddrinfo(host.c_str(), port.c_str(), &hints, &res);
  if (rc != 0 || !res) throw InputError(key + ": cannot resolve '" + text + "': " + ::gai_strerror(rc));
  UdpDestination d;
  d.text = text;
  std::memcpy(&d.address, res->ai_addr, res->ai_addrlen);
  d.length = res->ai_addrlen;
  ::freeaddrinfo(res);
  return d;
}

UdpPoseSender::UdpPoseSender(std::vector<UdpDestination> destinations) : destinations_(std::move(destinations)) {
  for (const auto& d : destinations_) {
    int& s = d.address.ss_family == AF_INET6 ? socket6_ : socket4_;
    if (s >= 0) continue;
    s = ::socket(d.address.ss_family, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (s < 0)
      throw InputError("publish.udp.destinations: cannot create a socket for '" + d.text +
                       "': " + std::strerror(errno));
    // A broadcast destination (a subnet's .255, 255.255.255.255) is refused with EACCES without it.
    const int on = 1;
    if (d.address.ss_family == AF_INET) ::setsockopt(s, SOL_SOCKET, SO_BROADCAST, &on, sizeof(on));
  }
}

UdpPoseSender::~UdpPoseSender() {
  if (socket4_ >= 0) ::close(socket4_);
  if (socket6_ >= 0) ::close(socket6_);
}

void UdpPoseSender::send(const pose::PoseRecord& record) {
  if (destinations_.empty()) return;
  uint8_t bytes[pose::kPacketSize];
  pose::encodePacket(record, bytes);
  for (const auto& d : destinations_) {
    const int s = d.address.ss_family == AF_INET6 ? socket6_ : socket4_;
    const ssize_t n = ::sendto(s, bytes, sizeof(bytes), MSG_DONTWAIT | MSG_NOSIGNAL,
                               reinterpret_cast<const sockaddr*>(&d.address), d.length);
    if (n == static_cast<ssize_t>(sizeof(bytes)))
      sent_.fetch_add(1, std::memory_order_relaxed);
    else {
      last_errno_.store(n < 0 ? errno : EMSGSIZE, std::memory_order_relaxed);
      failed_.fetch_add(1, std::memory_order_relaxed);
    }
  }
}

}  // namespace mcslam::platform
