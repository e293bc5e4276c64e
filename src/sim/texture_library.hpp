#pragma once
// Resolves (kind, variant) requests to textures and generates them: procedural paintings seeded by the world
// seed, or, with a photo folder, the photographs (mirror-tiled so that they repeat without seams).
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "mcslam/sim/world.hpp"
#include "mip_texture.hpp"

namespace mcslam {
class WorkerPool;
}

namespace mcslam::sim {

class TextureLibrary {
 public:
  // Throws InputError when photos_dir is given but holds no readable PNG/JPG.
  TextureLibrary(uint64_t seed, const std::string& photos_dir);

  int request(TextureKind kind, int variant);
  bool usesPhotos() const { return !photos_.empty(); }
  // Texel size to use for a tiled photograph (it spans about 1.5 m).
  double photoTexelSize(int index) const;
  // Generates every requested texture, in request order.
  std::vector<MipTexture> generate(WorkerPool& pool) const;

 private:
  uint64_t seed_;
  std::vector<std::string> photos_;
  std::map<std::pair<int, int>, int> index_;
  std::vector<std::pair<TextureKind, int>> requests_;
  std::vector<int> photo_of_request_;
};

}  // namespace mcslam::sim
