#pragma once
// Internal representation of a World, shared by the builder, the light baker and the renderer.
// Geometry is kept in float: it is what the per-pixel code reads, and it is exact enough (1e-6 relative).
#include <string>
#include <vector>

#include "bvh.hpp"
#include "mcslam/sim/world.hpp"
#include "mip_texture.hpp"
#include "primitive.hpp"

namespace mcslam::sim::detail {

// One face's appearance after the materials have been resolved to textures.
struct FaceRecord {
  int32_t texture = -1;  // index in WorldData::textures, -1 = uniform albedo
  float su = 0, sv = 0;  // texels per metre along the face's u and v
  float ou = 0, ov = 0;  // texel offsets (so faces sharing a texture show different parts)
  float albedo = 0.5f;   // linear albedo (uniform) or factor on the texture's albedo
  float emission = 0.f;
  int32_t lightmap = -1;  // index in WorldData::lightmaps, -1 = shaded from its normal

  // Box faces only, precomputed for the renderer: with q the local hit point, texture coordinates are
  // (q[axis_u] * tex_u[0] + tex_u[1], q[axis_v] * tex_v[0] + tex_v[1]) and light-map cell coordinates likewise;
  // the face normal is local axis axis_n.
  uint8_t axis_u = 0, axis_v = 0, axis_n = 0;
  float tex_u[2] = {0, 0}, tex_v[2] = {0, 0};
  float lm_u[2] = {0, 0}, lm_v[2] = {0, 0};
};

struct LightmapRecord {
  std::size_t offset = 0;    // into WorldData::lightmap_values
  int w = 0, h = 0;          // cells along u and v
  float su = 5.f, sv = 5.f;  // cells per metre along u and v
};

struct WorldData {
  std::string name = "custom";
  uint64_t seed = 1;

  std::vector<Prim> prims;               // static objects, builder order
  std::vector<Material> face_materials;  // as given to the builder (one per face)
  std::vector<FaceRecord> faces;
  std::vector<MipTexture> textures;
  std::vector<LightmapRecord> lightmaps;
  std::vector<float> lightmap_values;  // irradiance
  Bvh bvh;

  std::vector<PointLight> lights;
  Vec3 sun_direction = Vec3(0.3, 0.2, 0.9).normalized();
  double sun_irradiance = 0.0;
  double ambient_open = 0.35, ambient_occluded = 0.08, ambient_range = 1.2;
  double sky_horizon = 0.0, sky_zenith = 0.0;
  double exposure = 0.4;

  RouteSpec route;
  std::vector<Walker> walkers;
  std::vector<uint32_t> walker_face0;  // faces of each walker's box (6 each, no light map)

  // Walker i as a box primitive at time t.
  Prim walkerPrim(int i, double t) const;
  SE3 walkerPose(int i, double t) const;
  // Irradiance of a face without a light map (moving objects), from its world normal.
  float unlitIrradiance(const Vec3& normal_w) const;
};

}  // namespace mcslam::sim::detail
