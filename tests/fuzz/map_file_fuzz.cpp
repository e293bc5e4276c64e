// The map file reader (places/map_contents.hpp, map_file.hpp): the bytes as they come (the envelope's checks), then
// with the envelope's payload size and CRC made to match, so that the fuzzer reaches the header and the payload
// behind them. Documented outcome for bad input: InputError.
#include <cstdint>
#include <cstring>
#include <string>

#include "fuzz_support.hpp"
#include "mcslam/core/checksum.hpp"
#include "mcslam/core/error.hpp"
#include "mcslam/places/map_contents.hpp"

namespace {

// The envelope: "MCSLMAP\0", u32 version, u64 payload size at 12, u32 CRC at 20, payload from 24 (map_file.hpp).
constexpr std::size_t kSizeAt = 12, kCrcAt = 20;

void read(const std::string& bytes) {
  try {
    (void)mcslam::readMapContents(bytes, "fuzz.mcmap");
  } catch (const mcslam::InputError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  std::string bytes = mcslam::fuzz::text(data, size);
  read(bytes);
  const std::size_t envelope = mcslam::mapEnvelopeBytes();
  if (size < envelope) return 0;
  const uint64_t payload = size - envelope;
  const uint32_t crc = mcslam::crc32(bytes.data() + envelope, payload);
  std::memcpy(bytes.data() + kSizeAt, &payload, sizeof payload);
  std::memcpy(bytes.data() + kCrcAt, &crc, sizeof crc);
  read(bytes);
  return 0;
}
