// Tiling surface materials: walls, floors, ground, vegetation. All seamless (periodic noise, patterns whose
// periods divide the canvas, wrapped decorations).
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "texture_kinds.hpp"
#include "texture_paint.hpp"

namespace mcslam::sim {

using namespace paint;

namespace {

cv::Mat canvas(int w, int h, float value) { return cv::Mat(h, w, CV_32F, cv::Scalar(value)); }

// Small dark and light specks (pores, grit): count, radius range, value offsets.
void speckle(cv::Mat& img, Rng& rng, int count, float rmin, float rmax, float lo, float hi) {
  for (int i = 0; i < count; ++i) {
    const cv::Point2f c(static_cast<float>(rng.uniform(0, img.cols)), static_cast<float>(rng.uniform(0, img.rows)));
    const float r = static_cast<float>(rng.uniform(rmin, rmax));
    const float v = static_cast<float>(rng.uniform(lo, hi));
    fillCircle(img, c, r, v, static_cast<float>(rng.uniform(0.5, 1.0)), true);
  }
}

// Soft large blotches (dirt, damp, wear) as a wrapped low-frequency field.
void blotches(cv::Mat& img, uint64_t seed, float amplitude, double period) {
  cv::Mat f = fbm(img.cols, img.rows, seed, period, period / 4, 0.8);
  // Emphasise a few patches rather than a uniform wash.
  cv::Mat pos;
  cv::max(f - 0.25, 0.0, pos);
  img -= pos * (amplitude / 0.75f);
}

// Thin irregular dark line (crack, scratch) as a random walk.
void crack(cv::Mat& img, Rng& rng, float value, float opacity, int steps, float step, float thickness) {
  cv::Point2f p(static_cast<float>(rng.uniform(0, img.cols)), static_cast<float>(rng.uniform(0, img.rows)));
  double heading = rng.uniform(0, 2 * M_PI);
  for (int i = 0; i < steps; ++i) {
    heading += rng.normal() * 0.35;
    const cv::Point2f q =
        p + cv::Point2f(static_cast<float>(std::cos(heading) * step), static_cast<float>(std::sin(heading) * step));
    drawLine(img, p, q, thickness, value, opacity, true);
    p = q;
  }
}

}  // namespace

PaintedTexture paintPlaster(uint64_t seed) {
  Rng rng(seed);
  cv::Mat img = canvas(512, 512, static_cast<float>(rng.uniform(0.70, 0.86)));
  addFbm(img, hashOf(seed, 1), 256, 32, 0.004f, 0.7);       // trowel and paint unevenness, faint
  addFbm(img, hashOf(seed, 2), 16, 1, 0.010f, 0.3);         // fine grain, only seen close up
  addFbm(img, hashOf(seed, 3), 512, 32, 0.004f, 0.5, 8.0);  // roller streaks
  return {img, true};
}

PaintedTexture paintConcrete(uint64_t seed) {
  Rng rng(seed);
  cv::Mat img = canvas(1024, 1024, static_cast<float>(rng.uniform(0.52, 0.66)));
  addFbm(img, hashOf(seed, 1), 512, 2, 0.10f, 1.0);
  blotches(img, hashOf(seed, 2), 0.10f, 512);
  speckle(img, rng, 2500, 0.6f, 2.2f, 0.15f, 0.35f);  // pores
  speckle(img, rng, 600, 0.6f, 1.5f, 0.75f, 0.85f);   // light grit
  // Formwork panel seams and tie holes, period 512 texels.
  const float seam = static_cast<float>(rng.uniform(0.30, 0.42));
  for (int k = 0; k < 2; ++k) {
    const float x = 64.f + 512.f * k;
    drawLine(img, {x, 0}, {x, 1024}, 2.f, seam, 0.6f, true);
    drawLine(img, {0, x + 100}, {1024, x + 100}, 2.f, seam, 0.6f, true);
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 2; ++i)
        fillCircle(img, {x + 128.f + 256.f * i, x + 228.f + 256.f * j}, 7.f, 0.22f, 0.9f, true);
    }
  }
  for (int i = 0; i < 3; ++i) crack(img, rng, 0.3f, 0.5f, 40, 6.f, 1.f);
  return {img, true};
}

PaintedTexture paintBrick(uint64_t seed) {
  Rng rng(seed);
  const int W = 1024, H = 1024, course = 32, length = 128, mortar = 4;
  cv::Mat img = canvas(W, H, 0);
  const float mortar_value = static_cast<float>(rng.uniform(0.55, 0.78));
  const float base = static_cast<float>(rng.uniform(0.32, 0.48));
  const cv::Mat edge_noise = fbm(W, H, hashOf(seed, 1), 16, 2, 0.6);
  for (int y = 0; y < H; ++y) {
    const int row = y / course;
    const int shift = (row % 2) * (length / 2);
    float* p = img.ptr<float>(y);
    const float* en = edge_noise.ptr<float>(y);
    for (int x = 0; x < W; ++x) {
      const int xs = (x + shift) % W;
      const int col = xs / length;
      const float dx = static_cast<float>(std::min(xs % length, length - 1 - xs % length));
      const float dy = static_cast<float>(std::min(y % course, course - 1 - y % course));
      const float edge = std::min(dx, dy) - mortar * 0.5f + 1.5f * en[x];  // chipped brick edges
      const float tone = static_cast<float>(unitFromHash(hashOf(seed, row, col)) - 0.5) * 0.22f;
      const float brick = base + tone;
      const float t = std::clamp(edge, 0.f, 1.f);
      p[x] = mortar_value + t * (brick - mortar_value);
    }
  }
  addFbm(img, hashOf(seed, 2), 128, 2, 0.06f, 0.9);
  speckle(img, rng, 1500, 0.5f, 1.5f, 0.15f, 0.3f);
  blotches(img, hashOf(seed, 3), 0.08f, 512);
  return {img, true};
}

PaintedTexture paintWoodPlanks(uint64_t seed) {
  Rng rng(seed);
  const int W = 1024, H = 1024, plank_h = 64, plank_len = 512;
  cv::Mat img = canvas(W, H, 0);
  const cv::Mat warp = fbm(W, H, hashOf(seed, 1), 256, 16, 0.8, 4.0);
  const cv::Mat fine = fbm(W, H, hashOf(seed, 2), 64, 2, 0.7, 16.0);
  const float base = static_cast<float>(rng.uniform(0.40, 0.62));
  for (int y = 0; y < H; ++y) {
    const int row = y / plank_h;
    const int offset = static_cast<int>(unitFromHash(hashOf(seed, 7, row)) * plank_len);
    float* p = img.ptr<float>(y);
    const float* wp = warp.ptr<float>(y);
    const float* fp = fine.ptr<float>(y);
    for (int x = 0; x < W; ++x) {
      const int xs = (x + offset) % W;
      const int col = xs / plank_len;
      const float tone = static_cast<float>(unitFromHash(hashOf(seed, row, col)) - 0.5) * 0.2f;
      const float grain = 0.5f + 0.5f * std::sin((y * 0.55f + 9.f * wp[x] + row * 3.1f) * 1.3f);
      float v = base + tone - 0.08f * grain * grain + 0.05f * fp[x];
      const int gx = std::min(xs % plank_len, plank_len - 1 - xs % plank_len);
      const int gy = std::min(y % plank_h, plank_h - 1 - y % plank_h);
      if (gx < 1 || gy < 1) v *= 0.45f;  // seams between boards
      p[x] = v;
    }
  }
  for (int i = 0; i < 12; ++i) {  // knots
    const cv::Point2f c(static_cast<float>(rng.uniform(0, W)), static_cast<float>(rng.uniform(0, H)));
    fillCircle(img, c, static_cast<float>(rng.uniform(3, 8)), base - 0.2f, 0.7f, true);
  }
  addFbm(img, hashOf(seed, 3), 512, 64, 0.04f, 0.6);
  return {img, true};
}

PaintedTexture paintWoodPanel(uint64_t seed) {
  Rng rng(seed);
  const int W = 512, H = 512;
  cv::Mat img = canvas(W, H, static_cast<float>(rng.uniform(0.35, 0.7)));
  const cv::Mat warp = fbm(W, H, hashOf(seed, 1), 128, 16, 0.8, 4.0);
  for (int y = 0; y < H; ++y) {
    float* p = img.ptr<float>(y);
    const float* wp = warp.ptr<float>(y);
    for (int x = 0; x < W; ++x) p[x] -= 0.05f * (0.5f + 0.5f * std::sin(y * 0.4f + 7.f * wp[x]));
  }
  addFbm(img, hashOf(seed, 2), 64, 2, 0.025f, 0.6, 16.0);
  return {img, true};
}

PaintedTexture paintTiles(uint64_t seed) {
  Rng rng(seed);
  const int W = 1024, H = 1024, tile = 256, grout = 3;
  cv::Mat img = canvas(W, H, static_cast<float>(rng.uniform(0.5, 0.7)));
  for (int j = 0; j < H / tile; ++j) {
    for (int i = 0; i < W / tile; ++i) {
      fillRect(img, cv::Rect(i * tile, j * tile, tile, tile),
               img.at<float>(0, 0) + static_cast<float>(rng.uniform(-0.05, 0.05)));
    }
  }
  addFbm(img, hashOf(seed, 1), 256, 8, 0.03f, 0.6);
  speckle(img, rng, 9000, 0.7f, 3.5f, 0.1f, 0.95f);  // terrazzo chips
  const float g = static_cast<float>(rng.uniform(0.25, 0.4));
  for (int k = 0; k < W / tile; ++k) {
    fillRect(img, cv::Rect(k * tile, 0, grout, H), g, 0.9f);
    fillRect(img, cv::Rect(0, k * tile, W, grout), g, 0.9f);
  }
  blotches(img, hashOf(seed, 2), 0.06f, 512);
  return {img, true};
}

PaintedTexture paintLinoleum(uint64_t seed) {
  Rng rng(seed);
  cv::Mat img = canvas(512, 512, static_cast<float>(rng.uniform(0.45, 0.62)));
  addFbm(img, hashOf(seed, 1), 128, 4, 0.05f, 0.5);
  speckle(img, rng, 800, 0.5f, 1.2f, 0.3f, 0.75f);
  blotches(img, hashOf(seed, 2), 0.05f, 256);
  return {img, true};
}

PaintedTexture paintCarpet(uint64_t seed) {
  Rng rng(seed);
  const int W = 1024, tile = 256;
  cv::Mat img = canvas(W, W, static_cast<float>(rng.uniform(0.25, 0.45)));
  const cv::Mat along = fbm(W, W, hashOf(seed, 1), 32, 2, 0.3, 6.0);
  const cv::Mat across = fbm(W, W, hashOf(seed, 2), 32, 2, 0.3, 1.0 / 6.0);
  for (int y = 0; y < W; ++y) {
    float* p = img.ptr<float>(y);
    for (int x = 0; x < W; ++x) {
      const bool flip = ((x / tile) + (y / tile)) % 2 == 1;  // carpet tiles laid in alternate directions
      p[x] += 0.07f * (flip ? across.at<float>(y, x) : along.at<float>(y, x)) + (flip ? 0.02f : -0.02f);
    }
  }
  addFbm(img, hashOf(seed, 3), 2, 1, 0.05f, 0.0);
  blotches(img, hashOf(seed, 4), 0.05f, 512);
  return {img, true};
}

PaintedTexture paintFabric(uint64_t seed) {
  Rng rng(seed);
  const int W = 512;
  cv::Mat img = canvas(W, W, static_cast<float>(rng.uniform(0.2, 0.6)));
  for (int y = 0; y < W; ++y) {
    float* p = img.ptr<float>(y);
    for (int x = 0; x < W; ++x) p[x] += (((x / 2) + (y / 2)) % 2 ? 0.04f : -0.04f);  // weave
  }
  addFbm(img, hashOf(seed, 1), 128, 2, 0.05f, 0.5);
  if (rng.chance(0.4)) {  // checked or striped pattern
    const int period = 32 * rng.integer(1, 3);
    for (int k = 0; k < W / period; ++k) fillRect(img, cv::Rect(k * period, 0, period / 4, W), 0.15f, 0.4f);
  }
  return {img, true};
}

PaintedTexture paintMetal(uint64_t seed) {
  Rng rng(seed);
  const int W = 512;
  cv::Mat img = canvas(W, W, static_cast<float>(rng.uniform(0.5, 0.75)));
  addFbm(img, hashOf(seed, 1), 64, 1, 0.05f, 0.3, 64.0);  // brushing
  addFbm(img, hashOf(seed, 2), 256, 32, 0.04f, 0.5);
  for (int i = 0; i < 25; ++i) {
    const cv::Point2f a(static_cast<float>(rng.uniform(0, W)), static_cast<float>(rng.uniform(0, W)));
    const cv::Point2f b =
        a + cv::Point2f(static_cast<float>(rng.uniform(-60, 60)), static_cast<float>(rng.uniform(-15, 15)));
    drawLine(img, a, b, 1.f, static_cast<float>(rng.uniform(0.3, 0.9)), 0.5f, true);
  }
  return {img, true};
}

PaintedTexture paintCeilingTiles(uint64_t seed) {
  Rng rng(seed);
  const int W = 512, tile = 256;
  cv::Mat img = canvas(W, W, static_cast<float>(rng.uniform(0.75, 0.86)));
  addFbm(img, hashOf(seed, 1), 128, 2, 0.03f, 0.3);
  speckle(img, rng, 3000, 0.5f, 1.2f, 0.45f, 0.6f);  // perforations
  for (int k = 0; k < W / tile; ++k) {
    fillRect(img, cv::Rect(k * tile, 0, 6, W), 0.92f, 1.f);  // T-bar grid
    fillRect(img, cv::Rect(0, k * tile, W, 6), 0.92f, 1.f);
    fillRect(img, cv::Rect(k * tile + 6, 0, 2, W), 0.5f, 0.6f);
    fillRect(img, cv::Rect(0, k * tile + 6, W, 2), 0.5f, 0.6f);
  }
  return {img, true};
}

PaintedTexture paintPaving(uint64_t seed) {
  Rng rng(seed);
  const int W = 1024, sw = 128, sh = 64, joint = 3;
  cv::Mat img = canvas(W, W, 0);
  const float base = static_cast<float>(rng.uniform(0.45, 0.62));
  for (int y = 0; y < W; ++y) {
    const int row = y / sh;
    const int shift = (row % 2) * sw / 2;
    float* p = img.ptr<float>(y);
    for (int x = 0; x < W; ++x) {
      const int xs = (x + shift) % W;
      const int col = xs / sw;
      const int gx = std::min(xs % sw, sw - 1 - xs % sw), gy = std::min(y % sh, sh - 1 - y % sh);
      const float tone = static_cast<float>(unitFromHash(hashOf(seed, row, col)) - 0.5) * 0.16f;
      p[x] = (gx < joint || gy < joint) ? base * 0.5f : base + tone;
    }
  }
  addFbm(img, hashOf(seed, 1), 256, 2, 0.06f, 0.8);
  speckle(img, rng, 2500, 0.5f, 1.5f, 0.2f, 0.8f);
  blotches(img, hashOf(seed, 2), 0.12f, 512);
  for (int i = 0; i < 4; ++i) crack(img, rng, 0.2f, 0.6f, 25, 5.f, 1.f);
  return {img, true};
}

PaintedTexture paintGrass(uint64_t seed) {
  Rng rng(seed);
  const int W = 1024;
  cv::Mat img = canvas(W, W, static_cast<float>(rng.uniform(0.22, 0.32)));
  addFbm(img, hashOf(seed, 1), 512, 32, 0.08f, 0.6);
  for (int i = 0; i < 30000; ++i) {  // blades
    const cv::Point2f a(static_cast<float>(rng.uniform(0, W)), static_cast<float>(rng.uniform(0, W)));
    const double ang = rng.uniform(-0.5, 0.5) - M_PI / 2;
    const double len = rng.uniform(4, 14);
    const cv::Point2f b =
        a + cv::Point2f(static_cast<float>(std::cos(ang) * len), static_cast<float>(std::sin(ang) * len));
    drawLine(img, a, b, 1.f, static_cast<float>(rng.uniform(0.1, 0.6)), 0.7f, true);
  }
  return {img, true};
}

PaintedTexture paintFoliage(uint64_t seed) {
  Rng rng(seed);
  const int W = 1024;
  cv::Mat img = canvas(W, W, 0.06f);
  for (double size = 40; size >= 3; size *= 0.7) {  // leaf clusters from large to small
    const int n = static_cast<int>(2.5e5 / (size * size)) + 200;
    for (int i = 0; i < n; ++i) {
      const cv::Point2f c(static_cast<float>(rng.uniform(0, W)), static_cast<float>(rng.uniform(0, W)));
      fillCircle(img, c, static_cast<float>(size * rng.uniform(0.3, 0.6)), static_cast<float>(rng.uniform(0.12, 0.55)),
                 0.85f, true);
    }
  }
  return {img, true};
}

PaintedTexture paintBark(uint64_t seed) {
  Rng rng(seed);
  const int W = 512;
  cv::Mat img = canvas(W, W, static_cast<float>(rng.uniform(0.25, 0.4)));
  addFbm(img, hashOf(seed, 1), 128, 2, 0.12f, 0.7, 1.0 / 8.0);  // vertical ridges
  for (int i = 0; i < 30; ++i) {
    const float x = static_cast<float>(rng.uniform(0, W));
    const float y = static_cast<float>(rng.uniform(0, W));
    drawLine(img, {x, y}, {x + static_cast<float>(rng.uniform(-6, 6)), y + static_cast<float>(rng.uniform(40, 140))},
             2.f, 0.08f, 0.8f, true);
  }
  return {img, true};
}

PaintedTexture paintAsphalt(uint64_t seed) {
  Rng rng(seed);
  const int W = 1024;
  cv::Mat img = canvas(W, W, static_cast<float>(rng.uniform(0.26, 0.36)));
  addFbm(img, hashOf(seed, 1), 4, 1, 0.08f, 0.0);
  addFbm(img, hashOf(seed, 2), 512, 16, 0.05f, 0.8);
  speckle(img, rng, 6000, 0.5f, 1.3f, 0.45f, 0.7f);
  blotches(img, hashOf(seed, 3), 0.08f, 512);
  for (int i = 0; i < 6; ++i) crack(img, rng, 0.1f, 0.7f, 40, 6.f, 1.5f);
  return {img, true};
}

PaintedTexture paintRadiator(uint64_t seed) {
  Rng rng(seed);
  const int W = 256;
  cv::Mat img = canvas(W, W, static_cast<float>(rng.uniform(0.75, 0.88)));
  for (int y = 0; y < W; ++y) {
    float* p = img.ptr<float>(y);
    for (int x = 0; x < W; ++x) p[x] -= 0.18f * std::pow(std::abs(std::sin(x * static_cast<float>(M_PI) / 16.f)), 6.f);
  }
  addFbm(img, hashOf(seed, 1), 64, 4, 0.02f, 0.5);
  return {img, true};
}

}  // namespace mcslam::sim
