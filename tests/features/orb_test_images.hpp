#pragma once
// Procedural, natural-looking test scenes for the ORB tests and benchmarks: multi-scale value noise
// (a 1/f-like spectrum), polygons with sharp edges, soft blobs, an illumination gradient. A scene is a
// continuous function, so a second view under a known homography is rendered from the scene itself
// (supersampled), not resampled from the first image.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "mcslam/core/image.hpp"

namespace mcslam::test {

class ProceduralScene {
 public:
  explicit ProceduralScene(uint64_t seed, double extent = 1024.0) : extent_(extent) {
    Rng rng{seed};
    for (auto& lattice : lattice_)
      for (float& v : lattice) v = static_cast<float>(rng.uniform() * 2.0 - 1.0);
    shapes_.resize(kShapes);
    for (Shape& s : shapes_) {
      s.cx = rng.uniform() * extent_;
      s.cy = rng.uniform() * extent_;
      s.radius = 4.0 + 70.0 * rng.uniform() * rng.uniform();
      s.sides = 3 + static_cast<int>(rng.uniform() * 4);  // 3..6 sides; 6 stands for a disc
      s.rotation = rng.uniform() * 6.283185307179586;
      s.level = (rng.uniform() * 2.0 - 1.0) * 80.0;
      s.soft = rng.uniform() < 0.25;
      s.prepare();
    }
    // Buckets of shapes by area, so a point only looks at the shapes that can cover it.
    for (int i = 0; i < kShapes; ++i) {
      const Shape& s = shapes_[static_cast<size_t>(i)];
      const double reach = s.radius * 1.6;
      for (int by = bucket(s.cy - reach); by <= bucket(s.cy + reach); ++by)
        for (int bx = bucket(s.cx - reach); bx <= bucket(s.cx + reach); ++bx)
          buckets_[static_cast<size_t>(by * kBuckets + bx)].push_back(i);
    }
  }

  // Intensity in [0, 255] at scene point (x, y).
  double operator()(double x, double y) const {
    // 1/f-like multi-scale texture down to a 2-unit period, sharp-edged shapes and blobs on top.
    double v = 0, amplitude = 50.0, period = 128.0;
    for (int o = 0; o < kOctaves; ++o, amplitude *= 0.8, period *= 0.5)
      v += amplitude * noise(o, x / period, y / period);
    if (x >= 0 && y >= 0 && x < extent_ && y < extent_)
      for (int i : buckets_[static_cast<size_t>(bucket(y) * kBuckets + bucket(x))]) {
        const Shape& s = shapes_[static_cast<size_t>(i)];
        v += s.level * s.coverage(x, y);
      }
    v += 30.0 * std::sin(x / extent_ * 2.1 + 0.3) * std::cos(y / extent_ * 1.7);  // illumination
    return std::clamp(128.0 + v, 0.0, 255.0);
  }

  // Renders the view whose pixel (u, v) sees scene point H * (u, v, 1), with s x s supersampling.
  // H maps pixel coordinates to scene coordinates (row-major 3x3).
  void render(const std::array<double, 9>& H, Image& out, int width, int height, int supersample = 2) const {
    out.resize(width, height);
    for (int v = 0; v < height; ++v) {
      uint8_t* row = out.row(v);
      for (int u = 0; u < width; ++u) {
        double sum = 0;
        for (int j = 0; j < supersample; ++j)
          for (int i = 0; i < supersample; ++i) {
            const double pu = u + (i + 0.5) / supersample - 0.5, pv = v + (j + 0.5) / supersample - 0.5;
            const double w = H[6] * pu + H[7] * pv + H[8];
            sum += (*this)((H[0] * pu + H[1] * pv + H[2]) / w, (H[3] * pu + H[4] * pv + H[5]) / w);
          }
        row[u] = static_cast<uint8_t>(std::lround(sum / (supersample * supersample)));
      }
    }
  }

 private:
  static constexpr int kOctaves = 7, kLattice = 64, kShapes = 700, kBuckets = 32;

  int bucket(double v) const { return std::clamp(static_cast<int>(v / extent_ * kBuckets), 0, kBuckets - 1); }

  struct Rng {
    uint64_t state;
    double uniform() {
      uint64_t z = (state += 0x9E3779B97F4A7C15ull);
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
      return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
    }
  };

  struct Shape {
    double cx, cy, radius, rotation, level;
    int sides;
    bool soft;
    double nx[6], ny[6];  // outward edge normals of a polygon

    void prepare() {
      for (int k = 0; k < sides && sides < 6; ++k) {
        const double a = rotation + 6.283185307179586 * (k + 0.5) / sides;
        nx[k] = std::cos(a);
        ny[k] = std::sin(a);
      }
    }
    double coverage(double x, double y) const {
      const double dx = x - cx, dy = y - cy;
      const double r2 = dx * dx + dy * dy, reach = radius * 1.6;
      if (r2 > reach * reach) return 0;
      if (soft) return std::exp(-r2 / (0.5 * radius * radius));  // a blob
      double inside;                                             // signed distance to the edge, positive inside
      if (sides >= 6) {
        inside = radius - std::sqrt(r2);
      } else {
        const double apothem = radius * std::cos(3.141592653589793 / sides);
        inside = 1e9;
        for (int k = 0; k < sides; ++k) inside = std::min(inside, apothem - (dx * nx[k] + dy * ny[k]));
      }
      return std::clamp(inside + 0.5, 0.0, 1.0);  // one pixel of edge
    }
  };

  // Smooth (cubic-faded) value noise on a periodic lattice.
  double noise(int octave, double x, double y) const {
    const double fx = std::floor(x), fy = std::floor(y);
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    auto at = [&](int i, int j) {
      return lattice_[octave][static_cast<size_t>(((j % kLattice + kLattice) % kLattice) * kLattice +
                                                  ((i % kLattice + kLattice) % kLattice))];
    };
    auto fade = [](double t) { return t * t * (3 - 2 * t); };
    const double tx = fade(x - fx), ty = fade(y - fy);
    const double top = at(ix, iy) + tx * (at(ix + 1, iy) - at(ix, iy));
    const double bottom = at(ix, iy + 1) + tx * (at(ix + 1, iy + 1) - at(ix, iy + 1));
    return top + ty * (bottom - top);
  }

  double extent_;
  std::array<std::array<float, kLattice * kLattice>, kOctaves> lattice_{};
  std::vector<Shape> shapes_;
  std::array<std::vector<int>, kBuckets * kBuckets> buckets_;
};

// Adds zero-mean pseudo-Gaussian sensor noise (seeded).
inline void addNoise(Image& image, double sigma, uint64_t seed) {
  uint64_t state = seed;
  auto uniform = [&] {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return static_cast<double>((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  };
  for (int y = 0; y < image.height(); ++y) {
    uint8_t* row = image.row(y);
    for (int x = 0; x < image.width(); ++x) {
      const double n = (uniform() + uniform() + uniform() + uniform() - 2.0) * 1.7320508 * sigma;
      row[x] = static_cast<uint8_t>(std::clamp(std::lround(row[x] + n), 0l, 255l));
    }
  }
}

// Similarity about the image centre then projective tilt, as a pixel -> scene homography:
// scene = T(offset) * R(angle) * S(1/scale) * [tilt], so the view shows the scene rotated by `angle`
// and magnified by `scale`.
inline std::array<double, 9> viewHomography(double cx, double cy, double angle, double scale, double offset_x,
                                            double offset_y, double tilt_x = 0, double tilt_y = 0) {
  const double c = std::cos(angle) / scale, s = std::sin(angle) / scale;
  // p_scene = A * (p - centre) + centre + offset, with a mild projective row.
  std::array<double, 9> H{c, -s, 0, s, c, 0, tilt_x, tilt_y, 1};
  // Fold the centring in: H * T(-centre), then T(centre + offset) * H.
  H[2] = -(c * cx - s * cy);
  H[5] = -(s * cx + c * cy);
  H[8] = 1 - tilt_x * cx - tilt_y * cy;
  for (int i = 0; i < 3; ++i) {
    H[i] += (cx + offset_x) * H[6 + i];
    H[3 + i] += (cy + offset_y) * H[6 + i];
  }
  return H;
}

inline void applyHomography(const std::array<double, 9>& H, double u, double v, double& x, double& y) {
  const double w = H[6] * u + H[7] * v + H[8];
  x = (H[0] * u + H[1] * v + H[2]) / w;
  y = (H[3] * u + H[4] * v + H[5]) / w;
}

// 3x3 inverse (adjugate / determinant).
inline std::array<double, 9> inverse(const std::array<double, 9>& m) {
  const double a = m[0], b = m[1], c = m[2], d = m[3], e = m[4], f = m[5], g = m[6], h = m[7], i = m[8];
  const double A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
  const double det = a * A + b * B + c * C;
  return {A / det, -(b * i - c * h) / det, (b * f - c * e) / det,
          B / det, (a * i - c * g) / det,  -(a * f - c * d) / det,
          C / det, -(a * h - b * g) / det, (a * e - b * d) / det};
}

// A textured 720x540-like frame (the benchmarks' input): the scene seen straight on, with noise.
inline Image texturedFrame(int width, int height, uint64_t seed) {
  ProceduralScene scene(seed);
  Image image;
  const std::array<double, 9> identity{1, 0, 100, 0, 1, 100, 0, 0, 1};
  scene.render(identity, image, width, height, 2);
  addNoise(image, 2.0, seed ^ 0x5eed);
  return image;
}

}  // namespace mcslam::test
