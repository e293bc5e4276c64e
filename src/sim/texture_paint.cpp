#include "texture_paint.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace mcslam::sim::paint {

namespace {

float smooth(float t) { return t * t * (3.f - 2.f * t); }

// One lattice row of values in [-1, 1]: a cheap xorshift stream seeded per row.
void latticeRow(uint64_t seed, int row, float* out, int n) {
  uint64_t state = mix64(seed ^ (0x9e3779b97f4a7c15ULL * static_cast<uint64_t>(row + 1))) | 1;
  for (int i = 0; i < n; ++i) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    out[i] = static_cast<float>(state >> 40) * (2.f / 16777216.f) - 1.f;
  }
}

}  // namespace

void addValueNoise(cv::Mat& img, uint64_t seed, int cells_x, int cells_y, float amplitude) {
  const int w = img.cols, h = img.rows;
  cells_x = std::max(1, cells_x);
  cells_y = std::max(1, cells_y);
  // Interpolate each lattice row along x once; texel rows then blend two of these (contiguous, vectorisable).
  std::vector<int> x0(w), x1(w);
  std::vector<float> wx(w);
  for (int x = 0; x < w; ++x) {
    const float fx = (x + 0.5f) * cells_x / static_cast<float>(w);
    const int i = static_cast<int>(std::floor(fx));
    x0[x] = ((i % cells_x) + cells_x) % cells_x;
    x1[x] = (x0[x] + 1) % cells_x;
    wx[x] = smooth(fx - static_cast<float>(i));
  }
  std::vector<float> rows(static_cast<std::size_t>(cells_y) * w);
  std::vector<float> lattice(cells_x);
  for (int j = 0; j < cells_y; ++j) {
    latticeRow(seed, j, lattice.data(), cells_x);
    float* r = &rows[static_cast<std::size_t>(j) * w];
    for (int x = 0; x < w; ++x) r[x] = lattice[x0[x]] + wx[x] * (lattice[x1[x]] - lattice[x0[x]]);
  }
  for (int y = 0; y < h; ++y) {
    const float fy = (y + 0.5f) * cells_y / static_cast<float>(h);
    const int j = static_cast<int>(std::floor(fy));
    const int y0 = ((j % cells_y) + cells_y) % cells_y, y1 = (y0 + 1) % cells_y;
    const float wy = smooth(fy - static_cast<float>(j));
    const float* __restrict r0 = &rows[static_cast<std::size_t>(y0) * w];
    const float* __restrict r1 = &rows[static_cast<std::size_t>(y1) * w];
    float* __restrict out = img.ptr<float>(y);
    const float a0 = amplitude * (1.f - wy), a1 = amplitude * wy;
    for (int x = 0; x < w; ++x) out[x] += a0 * r0[x] + a1 * r1[x];
  }
}

void addFbm(cv::Mat& img, uint64_t seed, double largest, double smallest, float amplitude, double beta,
            double stretch_x) {
  int octave = 0;
  for (double period = largest; period >= smallest * 0.999; period *= 0.5, ++octave) {
    const int cx = std::max(1, static_cast<int>(std::lround(img.cols / (period * stretch_x))));
    const int cy = std::max(1, static_cast<int>(std::lround(img.rows / period)));
    const float amp = amplitude * static_cast<float>(std::pow(period / largest, beta));
    addValueNoise(img, hashOf(seed, 0xfb3ULL, octave), cx, cy, amp);
  }
}

cv::Mat fbm(int w, int h, uint64_t seed, double largest, double smallest, double beta, double stretch_x) {
  cv::Mat m(h, w, CV_32F, cv::Scalar(0));
  addFbm(m, seed, largest, smallest, 1.f, beta, stretch_x);
  // Normalise to about [-1, 1] whatever the number of octaves.
  double lo, hi;
  cv::minMaxLoc(m, &lo, &hi);
  const double s = std::max(std::abs(lo), std::abs(hi));
  if (s > 1e-9) m *= 1.0 / s;
  return m;
}

void blendShape(cv::Mat& img, cv::Rect bounds, float value, float opacity, const DrawFn& draw) {
  const cv::Rect clipped = bounds & cv::Rect(0, 0, img.cols, img.rows);
  if (clipped.empty()) return;
  cv::Mat mask(bounds.height, bounds.width, CV_8U, cv::Scalar(0));
  draw(mask, bounds.tl());
  for (int y = clipped.y; y < clipped.y + clipped.height; ++y) {
    const uint8_t* m = mask.ptr<uint8_t>(y - bounds.y) + (clipped.x - bounds.x);
    float* p = img.ptr<float>(y) + clipped.x;
    for (int x = 0; x < clipped.width; ++x) {
      if (m[x] == 0) continue;
      const float a = opacity * m[x] * (1.f / 255.f);
      p[x] += a * (value - p[x]);
    }
  }
}

void blendShapeWrapped(cv::Mat& img, cv::Rect bounds, float value, float opacity, const DrawFn& draw) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const cv::Rect shifted = bounds + cv::Point(dx * img.cols, dy * img.rows);
      if ((shifted & cv::Rect(0, 0, img.cols, img.rows)).empty()) continue;
      const cv::Point shift(dx * img.cols, dy * img.rows);
      blendShape(img, shifted, value, opacity, [&](cv::Mat& mask, cv::Point offset) { draw(mask, offset - shift); });
    }
  }
}

void addShape(cv::Mat& img, cv::Rect bounds, float delta, const DrawFn& draw) {
  const cv::Rect clipped = bounds & cv::Rect(0, 0, img.cols, img.rows);
  if (clipped.empty()) return;
  cv::Mat mask(bounds.height, bounds.width, CV_8U, cv::Scalar(0));
  draw(mask, bounds.tl());
  for (int y = clipped.y; y < clipped.y + clipped.height; ++y) {
    const uint8_t* m = mask.ptr<uint8_t>(y - bounds.y) + (clipped.x - bounds.x);
    float* p = img.ptr<float>(y) + clipped.x;
    for (int x = 0; x < clipped.width; ++x) p[x] += delta * m[x] * (1.f / 255.f);
  }
}

void fillRect(cv::Mat& img, cv::Rect r, float value, float opacity) {
  r &= cv::Rect(0, 0, img.cols, img.rows);
  if (r.empty()) return;
  cv::Mat roi = img(r);
  if (opacity >= 1.f) {
    roi.setTo(value);
  } else {
    roi = roi * (1.f - opacity) + value * opacity;
  }
}

void fillCircle(cv::Mat& img, cv::Point2f c, float radius, float value, float opacity, bool wrap) {
  const int pad = 2;
  const cv::Rect bounds(static_cast<int>(std::floor(c.x - radius)) - pad,
                        static_cast<int>(std::floor(c.y - radius)) - pad, static_cast<int>(2 * radius) + 2 * pad + 2,
                        static_cast<int>(2 * radius) + 2 * pad + 2);
  const DrawFn draw = [&](cv::Mat& mask, cv::Point o) {
    // Sub-pixel centre and radius through OpenCV's fixed-point shift.
    constexpr int kShift = 4;
    const cv::Point cc(static_cast<int>(std::lround((c.x - o.x) * 16)),
                       static_cast<int>(std::lround((c.y - o.y) * 16)));
    cv::circle(mask, cc, std::max(1, static_cast<int>(std::lround(radius * 16))), cv::Scalar(255), cv::FILLED,
               cv::LINE_AA, kShift);
  };
  if (wrap)
    blendShapeWrapped(img, bounds, value, opacity, draw);
  else
    blendShape(img, bounds, value, opacity, draw);
}

void drawLine(cv::Mat& img, cv::Point2f a, cv::Point2f b, float thickness, float value, float opacity, bool wrap) {
  const int pad = static_cast<int>(thickness) + 3;
  const int x0 = static_cast<int>(std::floor(std::min(a.x, b.x))) - pad,
            y0 = static_cast<int>(std::floor(std::min(a.y, b.y))) - pad;
  const int x1 = static_cast<int>(std::ceil(std::max(a.x, b.x))) + pad,
            y1 = static_cast<int>(std::ceil(std::max(a.y, b.y))) + pad;
  const cv::Rect bounds(x0, y0, x1 - x0, y1 - y0);
  const DrawFn draw = [&](cv::Mat& mask, cv::Point o) {
    constexpr int kShift = 4;
    const cv::Point pa(static_cast<int>(std::lround((a.x - o.x) * 16)),
                       static_cast<int>(std::lround((a.y - o.y) * 16)));
    const cv::Point pb(static_cast<int>(std::lround((b.x - o.x) * 16)),
                       static_cast<int>(std::lround((b.y - o.y) * 16)));
    cv::line(mask, pa, pb, cv::Scalar(255), std::max(1, static_cast<int>(std::lround(thickness))), cv::LINE_AA, kShift);
  };
  if (wrap)
    blendShapeWrapped(img, bounds, value, opacity, draw);
  else
    blendShape(img, bounds, value, opacity, draw);
}

int drawText(cv::Mat& img, const std::string& text, cv::Point origin, int font, double scale, int thickness,
             float value, float opacity) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, font, scale, thickness, &baseline);
  const int pad = thickness + 2;
  const cv::Rect bounds(origin.x - pad, origin.y - size.height - pad, size.width + 2 * pad,
                        size.height + baseline + 2 * pad);
  blendShape(img, bounds, value, opacity, [&](cv::Mat& mask, cv::Point o) {
    cv::putText(mask, text, origin - o, font, scale, cv::Scalar(255), thickness, cv::LINE_AA);
  });
  return size.width;
}

void drawVerticalText(cv::Mat& img, const std::string& text, cv::Rect r, int font, double scale, int thickness,
                      float value) {
  if (r.width < 4 || r.height < 8) return;
  // Text drawn horizontally into an r.height x r.width mask, then rotated into the rectangle.
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, font, scale, thickness, &baseline);
  cv::Mat flat(r.width, r.height, CV_8U, cv::Scalar(0));
  const int x = std::max(2, (r.height - size.width) / 2);
  const int y = (r.width + size.height) / 2;
  cv::putText(flat, text, cv::Point(x, y), font, scale, cv::Scalar(255), thickness, cv::LINE_AA);
  cv::Mat rotated;
  cv::rotate(flat, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
  blendShape(img, r, value, 1.f, [&](cv::Mat& mask, cv::Point) { rotated.copyTo(mask); });
}

std::string randomWords(Rng& rng, int words, bool capitalise) {
  static const char* kCons = "bcdfghklmnprstvwz";
  static const char* kVow = "aeiouy";
  std::string s;
  for (int w = 0; w < words; ++w) {
    if (w) s += ' ';
    const int len = rng.integer(2, 8);
    for (int i = 0; i < len; ++i) {
      char ch = (i % 2 == 0) ? kCons[rng.integer(0, 16)] : kVow[rng.integer(0, 5)];
      if (capitalise && w == 0 && i == 0) ch = static_cast<char>(ch - 'a' + 'A');
      s += ch;
    }
  }
  return s;
}

std::string randomHeading(Rng& rng) {
  std::string s;
  const int len = rng.integer(3, 9);
  for (int i = 0; i < len; ++i) s += static_cast<char>('A' + rng.integer(0, 25));
  if (rng.chance(0.4)) {
    s += ' ';
    s += std::to_string(rng.integer(1, 999));
  }
  return s;
}

int randomFont(Rng& rng) {
  static const int kFonts[] = {cv::FONT_HERSHEY_SIMPLEX, cv::FONT_HERSHEY_DUPLEX, cv::FONT_HERSHEY_COMPLEX,
                               cv::FONT_HERSHEY_TRIPLEX, cv::FONT_HERSHEY_PLAIN,  cv::FONT_HERSHEY_COMPLEX_SMALL};
  return kFonts[rng.integer(0, 5)];
}

void gradientRect(cv::Mat& img, cv::Rect r, float top, float bottom) {
  r &= cv::Rect(0, 0, img.cols, img.rows);
  for (int y = r.y; y < r.y + r.height; ++y) {
    const float t = r.height > 1 ? static_cast<float>(y - r.y) / (r.height - 1) : 0.f;
    float* p = img.ptr<float>(y) + r.x;
    const float v = top + t * (bottom - top);
    for (int x = 0; x < r.width; ++x) p[x] = v;
  }
}

void bevel(cv::Mat& img, cv::Rect r, int width, float light, float dark) {
  fillRect(img, cv::Rect(r.x, r.y, r.width, width), light, 0.6f);
  fillRect(img, cv::Rect(r.x, r.y, width, r.height), light, 0.6f);
  fillRect(img, cv::Rect(r.x, r.y + r.height - width, r.width, width), dark, 0.6f);
  fillRect(img, cv::Rect(r.x + r.width - width, r.y, width, r.height), dark, 0.6f);
}

std::vector<uint8_t> toBytes(const cv::Mat& img) {
  std::vector<uint8_t> out(static_cast<std::size_t>(img.cols) * img.rows);
  for (int y = 0; y < img.rows; ++y) {
    const float* p = img.ptr<float>(y);
    uint8_t* o = out.data() + static_cast<std::size_t>(y) * img.cols;
    for (int x = 0; x < img.cols; ++x) {
      const float v = std::clamp(p[x], 0.f, 1.f) * 255.f + 0.5f;
      o[x] = static_cast<uint8_t>(v);
    }
  }
  return out;
}

}  // namespace mcslam::sim::paint
