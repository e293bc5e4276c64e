#pragma once
// Simulated worlds: textured boxes and cylinders (walls, furniture, facades, pillars, trees), lit by point
// lights, a sun and ambient light baked into light maps, plus optional moving boxes (pedestrians).
//
// World frame: z up, metres, the floor at z = 0. A World is immutable once built and safe to share between
// threads and renderers. Build your own with WorldBuilder or take a named one from makeWorld().
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mcslam/core/se3.hpp"

namespace mcslam::sim {

// Procedural texture families (each has many seeded variants). With WorldOptions::textures_dir the
// families listed as photographic in texture_kinds.cpp are replaced by photographs.
enum class TextureKind : uint8_t {
  Plaster,       // painted wall: almost featureless (the low-texture stretches)
  Concrete,      // multi-scale noise, pores, formwork seams
  Brick,         // running bond with mortar
  WoodPlanks,    // floor boards with grain
  WoodPanel,     // furniture laminate
  Tiles,         // terrazzo floor tiles with grout
  Linoleum,      // mottled, low contrast
  Carpet,        // carpet tiles
  Fabric,        // woven upholstery
  Metal,         // brushed metal
  CeilingTiles,  // acoustic ceiling grid
  Poster,        // printed graphics and text (use Material::fit)
  NoticeBoard,   // cork with pinned notes
  Whiteboard,    // marker scribbles
  Books,         // shelf rows of book spines
  Door,          // panel door (use Material::fit)
  Cabinet,       // doors and drawers with handles
  Facade,        // building front: storeys of windows
  Paving,        // paving stones
  Grass,
  Foliage,
  Bark,
  Asphalt,
  Person,    // clothing, for moving objects
  Radiator,  // vertical ribs
  Count
};
const char* textureKindName(TextureKind kind);

// Appearance of a face. Albedo is linear reflectance in [0, 1].
struct Material {
  bool textured = false;
  TextureKind kind = TextureKind::Plaster;
  int variant = -1;           // which texture of the family; -1 = picked from the seed and the face
  double albedo = 0.6;        // uniform albedo, or the factor applied to the texture's albedo
  double texel_size = 0.002;  // metres per texel when tiling (finer = smaller pattern)
  bool fit = false;           // stretch one copy of the texture over the face (posters, doors, markers)
  double emission = 0.0;      // self-emitted radiance, added after lighting (lamps, lit windows)
  bool lit = true;            // false: no baked lighting (faces nobody sees, e.g. the outside of walls)

  static Material uniform(double albedo) {
    Material m;
    m.albedo = albedo;
    return m;
  }
  static Material texture(TextureKind kind, double albedo_factor = 1.0, double texel_size = 0.002, int variant = -1) {
    Material m;
    m.textured = true;
    m.kind = kind;
    m.albedo = albedo_factor;
    m.texel_size = texel_size;
    m.variant = variant;
    return m;
  }
  static Material fitted(TextureKind kind, int variant = -1, double albedo_factor = 1.0) {
    Material m = texture(kind, albedo_factor, 0.002, variant);
    m.fit = true;
    return m;
  }
  // For faces that are never in view: skipped by the light baker.
  static Material unseen() {
    Material m = uniform(0.5);
    m.lit = false;
    return m;
  }
  static Material lamp(double emission) {
    Material m;
    m.albedo = 0.9;
    m.emission = emission;
    return m;
  }
};

// Face order of a box, in its own frame: -x, +x, -y, +y, -z, +z. Textures on side faces keep "up" along +z.
enum BoxFace { kBoxMinusX = 0, kBoxPlusX, kBoxMinusY, kBoxPlusY, kBoxMinusZ, kBoxPlusZ };
// Face order of a cylinder (axis = its own z): side, bottom cap, top cap.
enum CylinderFace { kCylinderSide = 0, kCylinderBottom, kCylinderTop };

struct PointLight {
  Vec3 position = Vec3::Zero();
  double intensity = 8.0;  // irradiance at 1 m facing the light
  double radius = 0.25;    // soft-shadow size of the emitter
  double range = 12.0;     // ignored beyond this distance (keeps baking cheap)
};

// Closed loop in the free space that ground and hand-held trajectories follow: a polygon whose corners are
// rounded with the given radii. Stops are corner indices where a ground robot pauses.
struct RouteSpec {
  std::vector<Vec2> corners;
  std::vector<double> radii;  // one per corner, metres
  std::vector<int> stops;     // corner indices
  double clearance = 0.45;    // required free distance around the route, metres (checked when trajectories are built)
};

// A person-sized box walking back and forth between two points (smooth turnarounds).
struct Walker {
  Vec2 a = Vec2::Zero(), b = Vec2(4, 0);
  double speed = 1.2;                          // peak speed, m/s
  double phase = 0.0;                          // seconds of offset along the cycle
  Vec3 half_extents = Vec3(0.15, 0.25, 0.87);  // along its walking direction, across, up
  int variant = -1;                            // Person texture variant
};

struct RayHit {
  double t = 0;  // distance along the (unit) ray, metres
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
  int object = -1;  // static object index (builder order), or walker index when moving
  int face = 0;     // BoxFace or CylinderFace
  bool moving = false;
};

namespace detail {
struct WorldData;
}

class World {
 public:
  explicit World(std::shared_ptr<const detail::WorldData> data);

  const std::string& name() const;
  uint64_t seed() const;
  // Closest surface along the ray origin + t * direction (the direction is normalised, t is in metres), up to
  // t_max. Moving objects are placed where they are at time_s (seconds).
  std::optional<RayHit> intersect(const Vec3& origin, const Vec3& direction, double t_max = 1e9, double time_s = 0.0,
                                  bool include_moving = true) const;
  const RouteSpec& route() const;
  // Axis-aligned bounds of the static geometry.
  std::pair<Vec3, Vec3> bounds() const;
  int staticObjectCount() const;
  int walkerCount() const;
  // Pose of walker i at time_s (its box centre and heading), for tests and overlays.
  SE3 walkerPose(int i, double time_s) const;
  // Camera gain that gives well exposed images in this world (the renderer's base exposure).
  double exposure() const;

  const detail::WorldData& data() const { return *data_; }

 private:
  std::shared_ptr<const detail::WorldData> data_;
};

class WorldBuilder {
 public:
  // textures_dir: folder of photographs (PNG/JPG) that replace the procedural textures; empty = procedural.
  explicit WorldBuilder(uint64_t seed = 1, std::string name = "custom", std::string textures_dir = "");
  ~WorldBuilder();
  WorldBuilder(WorldBuilder&&) noexcept;

  uint64_t seed() const { return seed_; }

  // Returns the object index. T_w_o places the box centre; half_extents along its own axes.
  int addBox(const SE3& T_w_o, const Vec3& half_extents, const Material& material);
  int addBox(const SE3& T_w_o, const Vec3& half_extents, const std::array<Material, 6>& faces);
  // Axis-aligned convenience: from min corner to max corner.
  int addBox(const Vec3& min_corner, const Vec3& max_corner, const Material& material);
  // Cylinder along its own z axis, centred at T_w_o.
  int addCylinder(const SE3& T_w_o, double radius, double half_height, const Material& side, const Material& caps);
  // A thin panel (poster, marker, door leaf): centre, outward normal, up direction, size; its front face shows
  // `front` (usually fitted), the rest `back`.
  int addPanel(const Vec3& centre, const Vec3& normal, const Vec3& up, double width, double height,
               const Material& front, const Material& back, double thickness = 0.002);

  void addLight(const PointLight& light);
  // Sun: direction towards the sun (any length) and the irradiance it gives a surface facing it.
  void setSun(const Vec3& towards_sun, double irradiance);
  // Ambient (indirect) irradiance: `open` for unoccluded directions, `occluded` for directions blocked within
  // ambient_range (indoors a short range gives soft contact shadows; outdoors use a long one for sky visibility).
  void setAmbient(double open, double occluded, double ambient_range);
  // Radiance of rays that hit nothing: horizon and zenith (outdoor sky); 0 indoors.
  void setSky(double horizon, double zenith);
  void setExposure(double gain);
  void setRoute(RouteSpec route);
  void addWalker(const Walker& walker);
  // Light-map cell size in metres (smaller = sharper shadows, slower build).
  void setLightmapCell(double metres);

  // Generates textures, builds the acceleration structure and bakes the lighting (uses all cores).
  std::shared_ptr<const World> build();

 private:
  uint64_t seed_;
  std::string textures_dir_;
  std::unique_ptr<detail::WorldData> data_;
  double lightmap_cell_ = 0.2;
};

struct WorldOptions {
  uint64_t seed = 1;
  bool moving_objects = false;  // people-sized boxes walking through the scene, away from the route
  std::string textures_dir;     // photographs instead of procedural textures
};

// "indoor", "corridor", "courtyard".
std::vector<std::string> worldNames();
// One line per world for --help.
std::string describeWorlds();
// Throws InputError naming the unknown world and listing the known ones.
std::shared_ptr<const World> makeWorld(const std::string& name, const WorldOptions& options = {});

}  // namespace mcslam::sim
