#pragma once
// 8-bit grey images: a non-owning view and an owning buffer allocated once.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace mcslam {

struct ImageView {
  const uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  int stride = 0;  // bytes between rows

  bool empty() const { return data == nullptr || width <= 0 || height <= 0; }
  const uint8_t* row(int y) const { return data + static_cast<std::ptrdiff_t>(y) * stride; }
  uint8_t at(int x, int y) const { return row(y)[x]; }
};

// Owning grey image. resize() allocates only when the capacity grows, so an image sized at
// start-up is reused frame after frame without touching the heap.
class Image {
 public:
  Image() = default;
  Image(int width, int height) { resize(width, height); }

  void resize(int width, int height) {
    const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    if (n > pixels_.capacity()) pixels_.reserve(n);
    pixels_.resize(n);
    width_ = width;
    height_ = height;
  }
  int width() const { return width_; }
  int height() const { return height_; }
  uint8_t* data() { return pixels_.data(); }
  const uint8_t* data() const { return pixels_.data(); }
  uint8_t* row(int y) { return pixels_.data() + static_cast<std::ptrdiff_t>(y) * width_; }
  ImageView view() const { return {pixels_.data(), width_, height_, width_}; }

 private:
  std::vector<uint8_t> pixels_;
  int width_ = 0;
  int height_ = 0;
};

}  // namespace mcslam
