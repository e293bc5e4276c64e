#pragma once
// State of one rendered view: the camera pose, the moving objects placed at the frame time, every primitive's
// frame holding the camera centre, per-tile candidate lists, and the shading of surface hits (shading.cpp).
#include <cstdint>
#include <vector>

#include "camera_lut.hpp"
#include "simd4.hpp"
#include "world_data.hpp"

namespace mcslam::sim {

// Hit keys: 0 = nothing, else (primitive + 1) << 3 | face.
inline uint32_t makeKey(int prim, int face) {
  return ((static_cast<uint32_t>(prim) + 1) << 3) | static_cast<uint32_t>(face);
}
inline int keyPrim(uint32_t k) { return static_cast<int>(k >> 3) - 1; }
inline int keyFace(uint32_t k) { return static_cast<int>(k & 7); }

// A primitive that may be hit by a tile's rays, with what the ray test needs stored inline.
struct Candidate {
  float o[3];     // camera centre in the primitive's frame
  float h[3];     // half extents
  float near;     // no ray of the tile can hit it closer than this
  uint32_t prim;  // primitive index
  bool fast;      // axis-aligned box: slab test with the ray's shared inverse direction
};

class FrameContext {
 public:
  explicit FrameContext(const detail::WorldData& world);

  // Places the camera (T_w_c) and the moving objects (time_s).
  void setup(const SE3& T_w_c, double time_s);
  // Candidates of one tile of `lut`, sorted by distance, ending with a sentinel (near = infinity).
  void collectCandidates(const CameraLut& lut, int tile, std::vector<Candidate>& out) const;

  const detail::Prim& prim(int i) const { return i < n_static_ ? world_.prims[i] : dynamic_[i - n_static_]; }
  const float* localOrigin(int i) const { return &local_o_[3 * static_cast<std::size_t>(i)]; }
  const float* origin() const { return O_; }
  // Camera-frame bearing -> world direction (T: float, or f4 for four bearings).
  template <class T>
  void rotate(const T b[3], T d[3]) const {
    d[0] = R_[0] * b[0] + R_[1] * b[1] + R_[2] * b[2];
    d[1] = R_[3] * b[0] + R_[4] * b[1] + R_[5] * b[2];
    d[2] = R_[6] * b[0] + R_[7] * b[1] + R_[8] * b[2];
  }
  const float* rotation() const { return R_; }

  // Linear radiance leaving the surface hit `key` at distance t along world direction d; pixel_angle (radians)
  // sets the texture filter footprint.
  float shade(uint32_t key, float t, const float d[3], float pixel_angle) const;
  // Whether shadeQuad handles hits on surface `key` (box faces with a light map).
  bool quadShadable(uint32_t key) const;
  // shade() for four pixels whose centre rays all hit surface `key` (quadShadable): camera-frame bearings b,
  // distances t_hit, pixel angles. One texture level for the four, from their mean footprint.
  f4 shadeQuad(uint32_t key, f4 t_hit, const f4 b[3], f4 pixel_angle) const;
  // Radiance of a ray that hits nothing.
  float sky(const float d[3]) const;

 private:
  const detail::WorldData& world_;
  int n_static_ = 0;
  std::vector<detail::Prim> dynamic_;
  std::vector<float> local_o_;  // 3 per primitive (static, then dynamic)
  float O_[3] = {0, 0, 0};
  float R_[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // camera -> world, row-major
  std::vector<float> to_linear_;              // texture grey level x 4 -> linear albedo
};

}  // namespace mcslam::sim
