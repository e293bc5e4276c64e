#pragma once
// Ray-cast renderer: images of a World as seen by the cameras of a Rig, through mcslam::CameraModel.
//
// Every pixel's ray comes from CameraModel::unproject at the pixel centre (radtan and equidistant distortion
// exact per pixel, fisheyes beyond 90 degrees included). Textures are mip-mapped by the ray footprint, pixels
// on silhouettes and face borders are supersampled, lighting is baked in the World. A sensor model then adds
// exposure (per camera and drifting over time), vignetting, shot and read noise, gamma and 8-bit quantisation;
// optionally motion blur. Same inputs, same bytes, whatever the thread count.
//
// A Renderer is not thread-safe (it owns scratch buffers and a worker pool); use one per calling thread.
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "mcslam/calib/rig.hpp"
#include "mcslam/core/image.hpp"
#include "mcslam/sim/world.hpp"

namespace mcslam::sim {

// Metric depth per pixel, row-major; 0 where the ray hits nothing (sky) or the pixel is outside the lens's
// valid domain.
struct DepthImage {
  int width = 0, height = 0;
  std::vector<float> data;

  void resize(int w, int h) {
    width = w;
    height = h;
    data.resize(static_cast<std::size_t>(w) * h);
  }
  float at(int x, int y) const { return data[static_cast<std::size_t>(y) * width + x]; }
};

enum class DepthKind {
  OpticalAxisZ,  // z of the surface point in the camera frame (negative for fisheye rays beyond 90 degrees)
  Range          // distance from the camera centre along the ray
};

struct SensorOptions {
  bool noise = true;
  double read_noise = 0.0012;  // standard deviation in linear full-scale units (about 1.5 grey levels in shadows)
  double shot_noise = 1.5e-4;  // variance per unit of linear signal (photon noise)
  bool vignetting = true;
  double vignetting_strength = 0.45;  // gain 1 - s * sin^2(angle off the optical axis), at least 0.3
  bool exposure_variation = true;     // per-camera gain offsets (+-10%) and a slow common drift (+-12%)
  double gamma = 2.2;                 // output encoding (linear radiance -> grey level)
  double motion_blur_s = 0.0;         // exposure time for motion blur; 0 = instantaneous
  int motion_blur_samples = 5;        // sub-exposures when blurring (odd: the middle one gives the depth)
};

struct RenderOptions {
  int threads = 0;            // 0 = one per hardware thread
  bool anti_aliasing = true;  // supersample silhouette and face-border pixels
  int edge_samples = 8;       // samples per supersampled pixel
  int tile_size = 16;         // pixels per tile side (candidate culling granularity)
  uint64_t seed = 1;          // sensor noise and exposure drift
  DepthKind depth = DepthKind::OpticalAxisZ;
  SensorOptions sensor;
};

class Renderer {
 public:
  Renderer(std::shared_ptr<const World> world, Rig rig, RenderOptions options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  const Rig& rig() const { return rig_; }
  const World& world() const { return *world_; }
  const RenderOptions& options() const { return options_; }

  // Camera `cam` of the rig with the body at T_w_b, at time time_s (seconds: places moving objects and drives
  // the exposure drift). frame_key seeds the sensor noise (use the frame index). `image` (and `depth`) are resized
  // to the camera's resolution; they only reallocate when they grow.
  void render(int cam, const SE3& T_w_b, double time_s, uint64_t frame_key, Image& image, DepthImage* depth = nullptr);
  // The same with the body pose as a function of time, needed for motion blur (sampled over the exposure,
  // centred on time_s). Without blur it is evaluated at time_s only.
  void render(int cam, const std::function<SE3(double)>& T_w_b_at, double time_s, uint64_t frame_key, Image& image,
              DepthImage* depth = nullptr);

  // Linear gain applied to camera `cam` at time_s (world exposure x camera offset x drift).
  double exposureGain(int cam, double time_s) const;

 private:
  struct Impl;
  std::shared_ptr<const World> world_;
  Rig rig_;
  RenderOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mcslam::sim
