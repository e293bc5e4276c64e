// Two passes per view, both parallel over tiles:
//  1. visibility: per tile, the primitives whose bounds meet the tile's rays (BVH cone query, then the tile's
//     bounding planes), sorted by distance; rays traced four at a time against them.
//  2. shading: texture (mip level from the ray footprint) x baked irradiance, four pixels at a time where they
//     and their neighbours all see one face. Pixels whose 8 neighbours do not all see the same face are
//     anti-aliased by coverage: sub-pixel rays are traced and each face they hit is shaded once, weighted by its
//     share of the samples. The same pass turns each row's linear radiance into grey levels (sensor model), so
//     the radiance of the image never goes through memory (only motion blur accumulates it).
#include "mcslam/sim/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "camera_lut.hpp"
#include "frame_context.hpp"
#include "packet_trace.hpp"
#include "sensor_model.hpp"
#include "sim_pool.hpp"

namespace mcslam::sim {

struct Renderer::Impl {
  Impl(const RenderOptions& o, const detail::WorldData& world)
      : pool(poolWorkers(o.threads)), sensor(o.sensor, o.seed), ctx(world) {}

  WorkerPool pool;
  SensorModel sensor;
  FrameContext ctx;
  std::vector<std::shared_ptr<const CameraLut>> luts;
  const CameraLut* lut = nullptr;
  std::vector<uint32_t> key;    // per pixel: surface hit by the centre ray
  std::vector<float> t;         // and its distance
  std::vector<float> radiance;  // sum over the sub-exposures of motion blur
  std::vector<std::vector<Candidate>> tile_cands;
  // Sub-pixel offsets of the anti-aliasing samples, padded to whole packets of four with copies of the last.
  int n_samples = 0;
  std::vector<float> sample_x, sample_y;
  // Where the last shading pass of a render writes grey levels, and the sensor's per-render parameters.
  struct Output {
    Image* image = nullptr;
    float gain = 1.f;
    uint32_t stream = 0;  // noise stream of this frame and camera
  } out;

  void visibilityPass(int tile);
  // Rays of pixels x..x+n-1 (n <= 4) of row y as columns: bearing x, y, z and pixel angle (0 in lanes >= n).
  void quadRays(int x, int y, int n, f4 b[4]) const;
  // weight: share of this sub-exposure; accumulate: add to the radiance of the earlier ones; encode: last one,
  // write grey levels.
  void shadingPass(int tile, float weight, bool accumulate, bool encode, bool anti_aliasing);
  void shadeRow(int y, int x0, int x1, bool anti_aliasing, const std::vector<Candidate>& cands, float* values,
                float* gains) const;
  bool sameNeighbours(int x, int y) const;
  float shadePixel(int x, int y, bool anti_aliasing, const std::vector<Candidate>& cands) const;
  float antiAliased(int x, int y, const std::vector<Candidate>& cands) const;
  bool isEdge(int x, int y) const;
};

void Renderer::Impl::visibilityPass(int tile) {
  std::vector<Candidate>& cands = tile_cands[tile];
  ctx.collectCandidates(*lut, tile, cands);
  const int W = lut->width, H = lut->height, ts = lut->tile;
  const int tx = tile % lut->tiles_x, ty = tile / lut->tiles_x;
  const int x0 = tx * ts, x1 = std::min(W, x0 + ts), y1 = std::min(H, (ty + 1) * ts);
  int hint = -1;
  for (int y = ty * ts; y < y1; ++y) {
    for (int x = x0; x < x1; x += 4) {
      // Four bearings (x, y, z, pixel angle; angle 0 for invalid pixels and past the image's right edge) turned
      // into world directions.
      const int n = std::min(4, x1 - x);
      f4 b[4];
      quadRays(x, y, n, b);
      RayPacket rays;
      ctx.rotate(b, rays.d);
      rays.active = b[3] > 0.f;
      const std::size_t i = static_cast<std::size_t>(y) * W + x;
      if (n == 4) {
        tracePacket(ctx, cands, rays, hint, &key[i], &t[i]);
      } else {
        uint32_t keys[4];
        float ts4[4];
        tracePacket(ctx, cands, rays, hint, keys, ts4);
        std::copy_n(keys, n, &key[i]);
        std::copy_n(ts4, n, &t[i]);
      }
    }
  }
}

void Renderer::Impl::quadRays(int x, int y, int n, f4 b[4]) const {
  f4 r[4];
  const float* first = lut->ray(x, y);  // the quad lies in one tile row (tiles are multiples of 4 wide)
  for (int l = 0; l < 4; ++l) r[l] = l < n ? load4(first + 4 * l) : splat(0.f);
  transpose4(r, b);
}

bool Renderer::Impl::isEdge(int x, int y) const {
  const int W = lut->width, H = lut->height;
  const std::size_t i = static_cast<std::size_t>(y) * W + x;
  const uint32_t k = key[i];
  if (x > 0 && y > 0 && x < W - 1 && y < H - 1) {
    // Interior pixel: most see the same surface as all 8 neighbours; only then is validity worth checking.
    const uint32_t* a = &key[i - W];
    const uint32_t* c = &key[i + W];
    if (((a[-1] ^ k) | (a[0] ^ k) | (a[1] ^ k) | (key[i - 1] ^ k) | (key[i + 1] ^ k) | (c[-1] ^ k) | (c[0] ^ k) |
         (c[1] ^ k)) == 0) {
      return false;
    }
  }
  for (int dy = -1; dy <= 1; ++dy) {
    const int yy = y + dy;
    if (yy < 0 || yy >= H) continue;
    for (int dx = -1; dx <= 1; ++dx) {
      const int xx = x + dx;
      if (xx < 0 || xx >= W) continue;
      if (key[static_cast<std::size_t>(yy) * W + xx] != k && lut->valid(xx, yy)) return true;
    }
  }
  return false;
}

// Coverage anti-aliasing: sub-pixel rays from the ray differentials of the neighbouring pixels.
float Renderer::Impl::antiAliased(int x, int y, const std::vector<Candidate>& cands) const {
  const int W = lut->width, H = lut->height;
  const float* r = lut->ray(x, y);
  const int xa = std::max(0, x - 1), xb = std::min(W - 1, x + 1);
  const int ya = std::max(0, y - 1), yb = std::min(H - 1, y + 1);
  const float *ra = lut->ray(xa, y), *rb = lut->ray(xb, y), *rc = lut->ray(x, ya), *rd = lut->ray(x, yb);
  const bool okx = ra[3] > 0.f && rb[3] > 0.f, oky = rc[3] > 0.f && rd[3] > 0.f;
  float gx[3], gy[3];
  for (int c = 0; c < 3; ++c) {
    gx[c] = okx ? (rb[c] - ra[c]) / static_cast<float>(xb - xa) : 0.f;
    gy[c] = oky ? (rd[c] - rc[c]) / static_cast<float>(yb - ya) : 0.f;
  }
  const int n = n_samples;
  uint32_t keys[64];
  float dist[64], dirs[64][3];
  int hint = -1;
  for (int s0 = 0; s0 < n; s0 += 4) {
    const f4 sx = load4(&sample_x[s0]), sy = load4(&sample_y[s0]);
    f4 b[3];
    for (int k = 0; k < 3; ++k) b[k] = r[k] + sx * gx[k] + sy * gy[k];
    const f4 len2 = b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
    const f4 inv = lanes([&](int l) { return 1.f / std::sqrt(len2[l]); });
    for (int k = 0; k < 3; ++k) b[k] *= inv;
    RayPacket rays;
    ctx.rotate(b, rays.d);
    rays.active = i4{-1, -1, -1, -1};
    uint32_t k4[4];
    float t4[4];
    tracePacket(ctx, cands, rays, hint, k4, t4);
    for (int l = 0; l < 4 && s0 + l < n; ++l) {
      keys[s0 + l] = k4[l];
      dist[s0 + l] = t4[l];
      for (int k = 0; k < 3; ++k) dirs[s0 + l][k] = rays.d[k][l];
    }
  }
  // Shade each distinct surface once (at its first sample), weighted by how many samples saw it.
  float sum = 0.f;
  bool done[64] = {};
  for (int s = 0; s < n; ++s) {
    if (done[s]) continue;
    int count = 0;
    for (int q = s; q < n; ++q) {
      if (keys[q] == keys[s]) {
        done[q] = true;
        ++count;
      }
    }
    const float value = keys[s] ? ctx.shade(keys[s], dist[s], dirs[s], r[3]) : ctx.sky(dirs[s]);
    sum += value * static_cast<float>(count);
  }
  return sum / static_cast<float>(n);
}

// Whether the 14 neighbours of the four pixels from (x, y) all see the surface those see (then none of the four is
// an edge).
bool Renderer::Impl::sameNeighbours(int x, int y) const {
  const int W = lut->width, H = lut->height;
  if (x == 0 || y == 0 || x + 4 >= W || y + 1 >= H) return false;
  const uint32_t* c = &key[static_cast<std::size_t>(y) * W + x];
  const uint32_t k = c[0], *a = c - W, *b = c + W;
  uint32_t diff = (c[-1] ^ k) | (c[4] ^ k);
  for (int l = -1; l <= 4; ++l) diff |= (a[l] ^ k) | (b[l] ^ k);
  return diff == 0;
}

float Renderer::Impl::shadePixel(int x, int y, bool anti_aliasing, const std::vector<Candidate>& cands) const {
  const float* r = lut->ray(x, y);
  if (!(r[3] > 0.f)) return 0.f;
  if (anti_aliasing && isEdge(x, y)) return antiAliased(x, y, cands);
  const std::size_t i = static_cast<std::size_t>(y) * lut->width + x;
  float d[3];
  ctx.rotate(r, d);
  return key[i] ? ctx.shade(key[i], t[i], d, r[3]) : ctx.sky(d);
}

// Radiance of pixels [x0, x1) of row y into values[0, x1 - x0), their vignetting gains (0 outside the lens's
// domain) into gains. x0 is a multiple of 4 (tiles are). Four pixels that see one light-mapped box face are shaded
// together, those of them on an edge then anti-aliased one by one; a hit implies a valid pixel (rays outside the
// lens's domain are never traced).
void Renderer::Impl::shadeRow(int y, int x0, int x1, bool anti_aliasing, const std::vector<Candidate>& cands,
                              float* values, float* gains) const {
  const std::size_t row = static_cast<std::size_t>(y) * lut->width;
  for (int x = x0; x < x1; x += 4) {
    const int n = std::min(4, x1 - x);
    f4 b[4];
    quadRays(x, y, n, b);
    store4(gains + (x - x0), b[3] > 0.f ? sensor.vignette(b[2]) : splat(0.f));
    const uint32_t* k = &key[row + x];
    float* v = values + (x - x0);
    if (n == 4 && k[0] != 0 && ((k[1] ^ k[0]) | (k[2] ^ k[0]) | (k[3] ^ k[0])) == 0 && ctx.quadShadable(k[0])) {
      store4(v, ctx.shadeQuad(k[0], load4(&t[row + x]), b, b[3]));
      if (!anti_aliasing || sameNeighbours(x, y)) continue;
      for (int l = 0; l < 4; ++l) {
        if (isEdge(x + l, y)) v[l] = antiAliased(x + l, y, cands);
      }
    } else {
      for (int l = 0; l < n; ++l) v[l] = shadePixel(x + l, y, anti_aliasing, cands);
    }
  }
}

void Renderer::Impl::shadingPass(int tile, float weight, bool accumulate, bool encode, bool anti_aliasing) {
  const std::vector<Candidate>& cands = tile_cands[tile];
  const int W = lut->width, H = lut->height, ts = lut->tile;
  const int tx = tile % lut->tiles_x, ty = tile / lut->tiles_x;
  const int x0 = tx * ts, x1 = std::min(W, x0 + ts), y1 = std::min(H, (ty + 1) * ts);
  float values[64], gains[64];  // tiles are at most 64 pixels wide
  for (int y = ty * ts; y < y1; ++y) {
    shadeRow(y, x0, x1, anti_aliasing, cands, values, gains);
    const std::size_t row = static_cast<std::size_t>(y) * W;
    uint8_t* grey = encode ? out.image->row(y) : nullptr;
    for (int x = x0; x < x1; x += 4) {
      const int n = std::min(4, x1 - x);  // 4 but at the right edge of an image whose width is no multiple of 4
      const std::size_t i = row + x;
      f4 v = weight * load4(values + (x - x0), n);
      if (accumulate) v += load4(&radiance[i], n);
      if (!encode) {
        store4(&radiance[i], v, n);
        continue;
      }
      uint8_t q[4];
      const uint32_t index = static_cast<uint32_t>(i);
      sensor.encode4(v * out.gain, load4(gains + (x - x0), n), out.stream, index, n == 4 ? grey + x : q);
      if (n < 4) std::copy_n(q, n, grey + x);
    }
  }
}

namespace {

// Runs fn over the tiles in runs of neighbours: threads taking alternate tiles would write to the same cache lines
// (a tile's 16 bytes of an image row, the headers of neighbouring candidate lists) and bounce them between cores.
template <class Fn>
void runTiles(WorkerPool& pool, int tiles, const Fn& fn) {
  constexpr int kRun = 4;
  pool.forEach((tiles + kRun - 1) / kRun, [&](int run) {
    for (int tile = run * kRun; tile < std::min(tiles, (run + 1) * kRun); ++tile) fn(tile);
  });
}

}  // namespace

// ---- Renderer ----

Renderer::Renderer(std::shared_ptr<const World> world, Rig rig, RenderOptions options)
    : world_(std::move(world)), rig_(std::move(rig)), options_(options) {
  if (!world_) throw std::invalid_argument("Renderer: no world");
  options_.tile_size = std::clamp(options_.tile_size / 4 * 4, 4, 64);  // whole packets of four
  options_.edge_samples = std::clamp(options_.edge_samples, 1, 64);
  options_.sensor.motion_blur_samples = std::clamp(options_.sensor.motion_blur_samples | 1, 1, 63);
  impl_ = std::make_unique<Impl>(options_, world_->data());
  for (const RigCamera& c : rig_.cameras) {
    impl_->luts.push_back(CameraLut::get(c.model, options_.tile_size, impl_->pool));
  }
  // N-rooks pattern: every column and every row of an n x n grid holds one sample.
  const int n = options_.edge_samples;
  int stride = n > 2 ? 3 : 1;
  while (n > 2 && std::gcd(stride, n) != 1) ++stride;
  impl_->n_samples = n;
  for (int s = 0; s < (n + 3) / 4 * 4; ++s) {
    const int q = std::min(s, n - 1);
    impl_->sample_x.push_back((static_cast<float>(q) + 0.5f) / static_cast<float>(n) - 0.5f);
    impl_->sample_y.push_back((static_cast<float>((q * stride) % n) + 0.5f) / static_cast<float>(n) - 0.5f);
  }
}

Renderer::~Renderer() = default;

double Renderer::exposureGain(int cam, double time_s) const {
  return world_->exposure() * impl_->sensor.relativeGain(cam, time_s);
}

void Renderer::render(int cam, const SE3& T_w_b, double time_s, uint64_t frame_key, Image& image, DepthImage* depth) {
  render(
      cam, [&T_w_b](double) { return T_w_b; }, time_s, frame_key, image, depth);
}

void Renderer::render(int cam, const std::function<SE3(double)>& T_w_b_at, double time_s, uint64_t frame_key,
                      Image& image, DepthImage* depth) {
  if (cam < 0 || cam >= rig_.size()) throw std::out_of_range("Renderer::render: no camera " + std::to_string(cam));
  Impl& m = *impl_;
  m.lut = m.luts[cam].get();
  const int W = m.lut->width, H = m.lut->height;
  const std::size_t n = static_cast<std::size_t>(W) * H;
  m.key.resize(n);
  m.t.resize(n);
  m.tile_cands.resize(static_cast<std::size_t>(m.lut->tiles_x) * m.lut->tiles_y);
  image.resize(W, H);
  if (depth) depth->resize(W, H);

  const double blur = std::max(0.0, options_.sensor.motion_blur_s);
  const int subs = blur > 0 ? options_.sensor.motion_blur_samples : 1;
  if (subs > 1) m.radiance.resize(n);
  const int tiles = static_cast<int>(m.tile_cands.size());
  const uint64_t stream = hashOf(options_.seed, frame_key, static_cast<uint64_t>(cam));
  m.out = {&image, static_cast<float>(exposureGain(cam, time_s)), static_cast<uint32_t>(stream ^ (stream >> 32))};
  for (int s = 0; s < subs; ++s) {
    const double ts = subs == 1 ? time_s : time_s + blur * ((s + 0.5) / subs - 0.5);
    m.ctx.setup(T_w_b_at(ts) * rig_.T_b_c(cam), ts);
    runTiles(m.pool, tiles, [&m](int tile) { m.visibilityPass(tile); });
    if (depth && s == subs / 2) {
      const bool range = options_.depth == DepthKind::Range;
      m.pool.forEach(H, [&](int y) {
        for (int x = 0; x < W; ++x) {
          const std::size_t i = static_cast<std::size_t>(y) * W + x;
          depth->data[i] = m.key[i] ? (range ? m.t[i] : m.t[i] * m.lut->ray(x, y)[2]) : 0.f;
        }
      });
    }
    const float weight = 1.f / static_cast<float>(subs);
    const bool aa = options_.anti_aliasing;
    const bool last = s == subs - 1;
    runTiles(m.pool, tiles, [&m, weight, s, last, aa](int tile) { m.shadingPass(tile, weight, s > 0, last, aa); });
  }
}

}  // namespace mcslam::sim
