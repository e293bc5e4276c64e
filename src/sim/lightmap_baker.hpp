#pragma once
// Bakes the irradiance of every static face into a grid of cells (light maps): point lights and the sun with
// ray-traced shadows, and ambient light with occlusion. Rendering then reads one bilinear sample per pixel.
namespace mcslam {
class WorkerPool;
}
namespace mcslam::sim {
namespace detail {
struct WorldData;
}
void bakeLightmaps(detail::WorldData& world, double cell_size, WorkerPool& pool);
}  // namespace mcslam::sim
