#pragma once
// CRC-32 (IEEE 802.3, as zlib and PNG compute it): detects a corrupt file (vocabulary, map).
#include <cstddef>
#include <cstdint>

namespace mcslam {

// CRC of `size` bytes; pass a previous result as `crc` to continue it over a following block.
uint32_t crc32(const void* data, std::size_t size, uint32_t crc = 0);

}  // namespace mcslam
