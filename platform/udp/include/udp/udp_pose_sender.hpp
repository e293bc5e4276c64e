#pragma once
// Sends every pose as one datagram (pose_protocol.hpp) to the configured destinations. Destinations
// are resolved once at start; send() uses a non-blocking socket, never allocates and never waits:
// a datagram the kernel cannot take now is counted as failed and forgotten (the next pose is newer).
#include <netinet/in.h>
#include <sys/socket.h>

#include <atomic>
#include <string>
#include <vector>

#include "mcslam/pose_protocol.hpp"

namespace mcslam::platform {

struct UdpDestination {
  std::string text;  // "host:port" as configured
  sockaddr_storage address{};
  socklen_t length = 0;
};

// "host:port" or "[v6]:port" -> address. Throws InputError naming `key` and the text.
UdpDestination resolveUdpDestination(const std::string& text, const std::string& key);

class UdpPoseSender {
 public:
  // Throws InputError when a socket cannot be created.
  explicit UdpPoseSender(std::vector<UdpDestination> destinations);
  ~UdpPoseSender();
  UdpPoseSender(const UdpPoseSender&) = delete;
  UdpPoseSender& operator=(const UdpPoseSender&) = delete;

  void send(const pose::PoseRecord& record);
  uint64_t sent() const { return sent_.load(std::memory_order_relaxed); }
  uint64_t failed() const { return failed_.load(std::memory_order_relaxed); }
  int lastErrno() const { return last_errno_.load(std::memory_order_relaxed); }  // of the last failed send
  const std::vector<UdpDestination>& destinations() const { return destinations_; }

 private:
  std::vector<UdpDestination> destinations_;
  int socket4_ = -1, socket6_ = -1;
  std::atomic<uint64_t> sent_{0}, failed_{0};
  std::atomic<int> last_errno_{0};
};

}  // namespace mcslam::platform
