#pragma once
// One painter per TextureKind. Each returns a canvas (CV_32F, display values in [0, 1], power-of-two sizes)
// that depends only on the seed.
#include <opencv2/core.hpp>

#include "mcslam/sim/world.hpp"

namespace mcslam::sim {

struct PaintedTexture {
  cv::Mat image;
  bool tiles = true;  // seamless, sampled with wrap-around; false = fitted once (clamped)
};

PaintedTexture paintTexture(TextureKind kind, uint64_t seed);

// Kinds whose painters live in the two files below.
PaintedTexture paintPlaster(uint64_t seed);
PaintedTexture paintConcrete(uint64_t seed);
PaintedTexture paintBrick(uint64_t seed);
PaintedTexture paintWoodPlanks(uint64_t seed);
PaintedTexture paintWoodPanel(uint64_t seed);
PaintedTexture paintTiles(uint64_t seed);
PaintedTexture paintLinoleum(uint64_t seed);
PaintedTexture paintCarpet(uint64_t seed);
PaintedTexture paintFabric(uint64_t seed);
PaintedTexture paintMetal(uint64_t seed);
PaintedTexture paintCeilingTiles(uint64_t seed);
PaintedTexture paintPaving(uint64_t seed);
PaintedTexture paintGrass(uint64_t seed);
PaintedTexture paintFoliage(uint64_t seed);
PaintedTexture paintBark(uint64_t seed);
PaintedTexture paintAsphalt(uint64_t seed);
PaintedTexture paintRadiator(uint64_t seed);

PaintedTexture paintPoster(uint64_t seed);
PaintedTexture paintNoticeBoard(uint64_t seed);
PaintedTexture paintWhiteboard(uint64_t seed);
PaintedTexture paintBooks(uint64_t seed);
PaintedTexture paintDoor(uint64_t seed);
PaintedTexture paintCabinet(uint64_t seed);
PaintedTexture paintFacade(uint64_t seed);
PaintedTexture paintPerson(uint64_t seed);

}  // namespace mcslam::sim
