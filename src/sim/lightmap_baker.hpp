#pragma once
// Bakes the irradiance of every static face into a grid of cells (light maps): point lights and the sun with
// ray-traced shadows, and ambient light with occlusion. Rendering then reads one bilinear sample per pixel.
namespace mcslam::sim {
class ThreadPool;
namespace detail {
struct WorldData;
}
void bakeLightmaps(detail::WorldData& world, double cell_size, ThreadPool& pool);
}  // namespace mcslam::sim
