// WorldBuilder: collects objects and materials, then resolves textures, builds the BVH and bakes light maps.
#include <algorithm>
#include <cmath>

#include "hash.hpp"
#include "lightmap_baker.hpp"
#include "mcslam/core/error.hpp"
#include "sim_pool.hpp"
#include "texture_library.hpp"
#include "world_data.hpp"

namespace mcslam::sim {

using detail::FaceRecord;
using detail::Prim;
using detail::WorldData;

namespace {

// Fitted kinds get one texture per object unless a variant is given; tiling kinds share a few variants.
bool isFittedKind(TextureKind k) {
  switch (k) {
    case TextureKind::Poster:
    case TextureKind::NoticeBoard:
    case TextureKind::Whiteboard:
    case TextureKind::Books:
    case TextureKind::Door:
    case TextureKind::Cabinet:
    case TextureKind::Person: return true;
    default: return false;
  }
}
constexpr int kTilingVariants = 2;

// Affine maps from the local hit point to texture and light-map coordinates of every box face (see FaceRecord).
void precomputeBoxFace(FaceRecord& fr, int face, const float h[3], const detail::LightmapRecord* lm) {
  // u runs along axis a with sign su (the viewer's right), v along axis b upwards; see detail::faceUv.
  static const uint8_t kAxisU[6] = {1, 1, 0, 0, 0, 0}, kAxisV[6] = {2, 2, 2, 2, 1, 1};
  static const float kSignU[6] = {-1, 1, 1, -1, -1, 1};
  const int a = kAxisU[face], b = kAxisV[face];
  fr.axis_u = static_cast<uint8_t>(a);
  fr.axis_v = static_cast<uint8_t>(b);
  fr.axis_n = static_cast<uint8_t>(face >> 1);
  // u = s * q[a] + h[a], v = q[b] + h[b]; texture x = u * su + ou, y = ov - v * sv.
  fr.tex_u[0] = kSignU[face] * fr.su;
  fr.tex_u[1] = h[a] * fr.su + fr.ou;
  fr.tex_v[0] = -fr.sv;
  fr.tex_v[1] = fr.ov - h[b] * fr.sv;
  if (lm) {  // cell coordinates, centred: x = u * su - 0.5
    fr.lm_u[0] = kSignU[face] * lm->su;
    fr.lm_u[1] = h[a] * lm->su - 0.5f;
    fr.lm_v[0] = lm->sv;
    fr.lm_v[1] = h[b] * lm->sv - 0.5f;
  }
}

void precomputeBoxFaces(WorldData& d) {
  for (const Prim& p : d.prims) {
    if (p.type != detail::PrimType::Box) continue;
    for (int f = 0; f < 6; ++f) {
      FaceRecord& fr = d.faces[p.face0 + f];
      precomputeBoxFace(fr, f, p.h, fr.lightmap >= 0 ? &d.lightmaps[fr.lightmap] : nullptr);
    }
  }
  for (std::size_t w = 0; w < d.walkers.size(); ++w) {
    const float h[3] = {static_cast<float>(d.walkers[w].half_extents.x()),
                        static_cast<float>(d.walkers[w].half_extents.y()),
                        static_cast<float>(d.walkers[w].half_extents.z())};
    for (int f = 0; f < 6; ++f) precomputeBoxFace(d.faces[d.walker_face0[w] + f], f, h, nullptr);
  }
}

}  // namespace

WorldBuilder::WorldBuilder(uint64_t seed, std::string name, std::string textures_dir)
    : seed_(seed), data_(std::make_unique<WorldData>()) {
  data_->name = std::move(name);
  data_->seed = seed;
  textures_dir_ = std::move(textures_dir);
}

WorldBuilder::~WorldBuilder() = default;
WorldBuilder::WorldBuilder(WorldBuilder&&) noexcept = default;

int WorldBuilder::addBox(const SE3& T_w_o, const Vec3& half_extents, const std::array<Material, 6>& faces) {
  if (!(half_extents.minCoeff() >= 0.0)) throw std::invalid_argument("addBox: negative half extent");
  const auto face0 = static_cast<uint32_t>(data_->face_materials.size());
  const Mat3& R = T_w_o.R;
  // A box turned by a multiple of 90 degrees is the same box unturned, with its faces and extents permuted:
  // axis-aligned boxes are much cheaper to ray-cast. Face coordinates are intrinsic (viewer's right, up), so
  // the look is unchanged.
  bool permutation = true;
  for (int i = 0; i < 9 && permutation; ++i) {
    const double v = std::abs(R(i / 3, i % 3));
    permutation = v < 1e-12 || std::abs(v - 1) < 1e-12;
  }
  if (permutation && std::abs(R(2, 2) - 1) < 1e-12) {
    Vec3 half;
    std::array<Material, 6> world_faces;
    for (int k = 0; k < 3; ++k) {
      const Vec3 axis = R.col(k);  // local axis k in the world
      int j = 0;
      axis.cwiseAbs().maxCoeff(&j);
      half[j] = half_extents[k];
      const bool flip = axis[j] < 0;
      world_faces[2 * j] = faces[2 * k + (flip ? 1 : 0)];
      world_faces[2 * j + 1] = faces[2 * k + (flip ? 0 : 1)];
    }
    data_->prims.push_back(Prim::box(SE3(Mat3::Identity(), T_w_o.t), half, face0));
    for (const Material& m : world_faces) data_->face_materials.push_back(m);
  } else {
    data_->prims.push_back(Prim::box(T_w_o, half_extents, face0));
    for (const Material& m : faces) data_->face_materials.push_back(m);
  }
  return static_cast<int>(data_->prims.size()) - 1;
}

int WorldBuilder::addBox(const SE3& T_w_o, const Vec3& half_extents, const Material& material) {
  std::array<Material, 6> faces;
  faces.fill(material);
  return addBox(T_w_o, half_extents, faces);
}

int WorldBuilder::addBox(const Vec3& min_corner, const Vec3& max_corner, const Material& material) {
  return addBox(SE3(Mat3::Identity(), 0.5 * (min_corner + max_corner)), 0.5 * (max_corner - min_corner).cwiseAbs(),
                material);
}

int WorldBuilder::addCylinder(const SE3& T_w_o, double radius, double half_height, const Material& side,
                              const Material& caps) {
  const auto face0 = static_cast<uint32_t>(data_->face_materials.size());
  data_->prims.push_back(Prim::cylinder(T_w_o, radius, half_height, face0));
  data_->face_materials.push_back(side);
  data_->face_materials.push_back(caps);
  data_->face_materials.push_back(caps);
  return static_cast<int>(data_->prims.size()) - 1;
}

int WorldBuilder::addPanel(const Vec3& centre, const Vec3& normal, const Vec3& up, double width, double height,
                           const Material& front, const Material& back, double thickness) {
  // Local frame: x = normal, so the front is the +x face, which shows u along +y and v along +z; hence
  // y = up x normal (the right of a viewer facing the panel) and z = up.
  const Vec3 n = normal.normalized();
  const Vec3 z = (up - up.dot(n) * n).normalized();
  const Vec3 y = z.cross(n);
  Mat3 R;
  R.col(0) = n;
  R.col(1) = y;
  R.col(2) = z;
  std::array<Material, 6> faces;
  faces.fill(back);
  faces[kBoxPlusX] = front;
  return addBox(SE3(R, centre), Vec3(0.5 * thickness, 0.5 * width, 0.5 * height), faces);
}

void WorldBuilder::addLight(const PointLight& light) { data_->lights.push_back(light); }

void WorldBuilder::setSun(const Vec3& towards_sun, double irradiance) {
  data_->sun_direction = towards_sun.normalized();
  data_->sun_irradiance = irradiance;
}

void WorldBuilder::setAmbient(double open, double occluded, double ambient_range) {
  data_->ambient_open = open;
  data_->ambient_occluded = occluded;
  data_->ambient_range = ambient_range;
}

void WorldBuilder::setSky(double horizon, double zenith) {
  data_->sky_horizon = horizon;
  data_->sky_zenith = zenith;
}

void WorldBuilder::setExposure(double gain) { data_->exposure = gain; }
void WorldBuilder::setRoute(RouteSpec route) { data_->route = std::move(route); }
void WorldBuilder::setLightmapCell(double metres) { lightmap_cell_ = std::max(0.02, metres); }

void WorldBuilder::addWalker(const Walker& walker) {
  data_->walker_face0.push_back(static_cast<uint32_t>(data_->face_materials.size()));
  const int variant = walker.variant >= 0 ? walker.variant : 1000 + static_cast<int>(data_->walkers.size());
  for (int f = 0; f < 6; ++f) data_->face_materials.push_back(Material::fitted(TextureKind::Person, variant));
  data_->walkers.push_back(walker);
}

namespace {

// Which object owns each face (fitted textures are unique per object), and the face's index within it.
struct FaceOwners {
  std::vector<int> owner;  // prim index, -1 for a walker's face
  std::vector<int> face_in_owner;
};

FaceOwners faceOwners(const WorldData& d) {
  const std::size_t n_faces = d.face_materials.size();
  FaceOwners fo{std::vector<int>(n_faces, -1), std::vector<int>(n_faces, 0)};
  for (std::size_t i = 0; i < d.prims.size(); ++i) {
    for (int f = 0; f < d.prims[i].faceCount(); ++f) {
      fo.owner[d.prims[i].face0 + f] = static_cast<int>(i);
      fo.face_in_owner[d.prims[i].face0 + f] = f;
    }
  }
  for (std::size_t w = 0; w < d.walkers.size(); ++w) {
    for (int f = 0; f < 6; ++f) fo.face_in_owner[d.walker_face0[w] + f] = f;
  }
  return fo;
}

// Every face's record from its material, the textured ones with their texture requested from the library.
void requestTextures(WorldData& d, const FaceOwners& fo, uint64_t seed, TextureLibrary& library) {
  const std::size_t n_faces = d.face_materials.size();
  d.faces.assign(n_faces, FaceRecord{});
  for (std::size_t i = 0; i < n_faces; ++i) {
    const Material& m = d.face_materials[i];
    FaceRecord& fr = d.faces[i];
    fr.emission = static_cast<float>(m.emission);
    if (!m.textured) {
      fr.albedo = static_cast<float>(std::clamp(m.albedo, 0.0, 1.0));
      continue;
    }
    int variant = m.variant;
    if (variant < 0) {
      variant = isFittedKind(m.kind) ? fo.owner[i] : static_cast<int>(hashOf(seed, i, 77) % kTilingVariants);
    }
    fr.texture = library.request(m.kind, variant);
    fr.albedo = static_cast<float>(m.albedo);
  }
}

// Texture coordinates: fitted faces span the texture once, tiled faces repeat it at the material's texel size
// from a random offset.
void mapTextures(WorldData& d, const FaceOwners& fo, uint64_t seed, const TextureLibrary& library) {
  const std::vector<int>& owner = fo.owner;
  const std::vector<int>& face_in_owner = fo.face_in_owner;
  auto faceExtent = [&](std::size_t i, float& w, float& h) {
    if (owner[i] >= 0) {
      detail::faceSize(d.prims[owner[i]], face_in_owner[i], w, h);
      return;
    }
    for (std::size_t k = 0; k < d.walkers.size(); ++k) {  // walker faces
      if (i >= d.walker_face0[k] && i < d.walker_face0[k] + 6) {
        const Prim p = Prim::box(SE3(), d.walkers[k].half_extents, 0);
        detail::faceSize(p, face_in_owner[i], w, h);
        return;
      }
    }
    w = h = 1.f;
  };
  for (std::size_t i = 0; i < d.faces.size(); ++i) {
    FaceRecord& fr = d.faces[i];
    if (fr.texture < 0) continue;
    const Material& m = d.face_materials[i];
    const MipTexture& tex = d.textures[fr.texture];
    float fw, fh;
    faceExtent(i, fw, fh);
    const bool photo = library.photoTexelSize(fr.texture) > 0;
    if (m.fit) {
      const float span = photo ? 0.5f : 1.0f;  // a mirrored photo: use one copy
      fr.su = span * tex.width() / std::max(fw, 1e-4f);
      fr.sv = span * tex.height() / std::max(fh, 1e-4f);
      fr.ou = 0.f;
      fr.ov = span * tex.height();
    } else {
      const double texel = photo ? library.photoTexelSize(fr.texture) : m.texel_size;
      fr.su = fr.sv = static_cast<float>(1.0 / texel);
      if (owner[i] >= 0 && d.prims[owner[i]].type == detail::PrimType::Cylinder && face_in_owner[i] == 0) {
        // Whole periods around a cylinder, so the seam does not show.
        const double periods = std::max(1.0, std::round(static_cast<double>(fw) * fr.su / tex.width()));
        fr.su = static_cast<float>(periods * tex.width() / fw);
      }
      Rng rng(hashOf(seed, i, 91));
      fr.ou = static_cast<float>(rng.uniform(0, tex.width()));
      fr.ov = static_cast<float>(rng.uniform(0, tex.height()));
    }
  }
}

}  // namespace

std::shared_ptr<const World> WorldBuilder::build() {
  if (!data_) throw std::logic_error("WorldBuilder::build called twice");
  WorldData& d = *data_;
  TextureLibrary library(seed_, textures_dir_);
  WorkerPool pool(poolWorkers(0));
  const FaceOwners owners = faceOwners(d);
  requestTextures(d, owners, seed_, library);
  d.textures = library.generate(pool);
  mapTextures(d, owners, seed_, library);
  d.bvh.build(d.prims);
  bakeLightmaps(d, lightmap_cell_, pool);
  precomputeBoxFaces(d);
  std::shared_ptr<const WorldData> frozen(std::move(data_));
  return std::make_shared<const World>(frozen);
}

}  // namespace mcslam::sim
