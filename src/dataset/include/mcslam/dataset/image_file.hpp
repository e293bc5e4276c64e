#pragma once
// Grey 8-bit image files, as datasets hold them.
//
// Binary PGM (P5, maxval 255) is read here, by our own reader: no codec library, and no allocation once the
// Image has the size. Every other format (PNG, JPEG, other PGM variants, ...) is decoded by the image codec
// module (mcslam_image_codec.so, OpenCV imgcodecs), loaded with dlopen the first time such a file is read: a
// process that never meets one (mcslamd on cameras, or replaying PGM) never maps imgcodecs and the ~110
// libraries it pulls in. The module is looked for next to the executable (../lib/mcslam/), in the build tree
// and in the install folder (imageCodecModuleCandidates()).
#include <string>
#include <vector>

#include "mcslam/core/image.hpp"

namespace mcslam {

// The largest image a read accepts (0: no bound on that side). A file whose header says it is larger is refused
// before its pixels are read or decoded: a compressed file may claim a size whose pixels would take gigabytes.
// PGM, PNG and JPEG are checked before decoding; other formats after.
struct ImageBound {
  int width = 0, height = 0;
  bool admits(int w, int h) const { return (width <= 0 || w <= width) && (height <= 0 || h <= height); }
};

// Reads the image at `path` as 8-bit grey into `image` (resized; its buffer only grows). The format is told by
// the content, not the name. Throws InputError naming the file: unreadable, malformed or truncated PGM,
// undecodable image, larger than `bound`, or the codec module missing (then naming the module paths tried).
void readGreyImageFile(const std::string& path, Image& image, ImageBound bound = {});

// Binary 8-bit PGM only (P5, maxval 255, '#' comments allowed in the header). Throws InputError naming the file
// and what is wrong (magic, size, maxval, truncated pixels).
void readPgmFile(const std::string& path, Image& image, ImageBound bound = {});

// Writes `image` as binary PGM (P5, maxval 255). Throws InputError naming the file when it cannot.
void writePgmFile(const std::string& path, const ImageView& image);

// Where the image codec module is looked for, in order.
std::vector<std::string> imageCodecModuleCandidates();

}  // namespace mcslam
