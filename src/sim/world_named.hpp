#pragma once
// Builders of the named worlds (one file each).
#include <memory>

#include "mcslam/sim/world.hpp"

namespace mcslam::sim {

std::shared_ptr<const World> buildIndoorWorld(const WorldOptions& options);
std::shared_ptr<const World> buildCorridorWorld(const WorldOptions& options);
std::shared_ptr<const World> buildCourtyardWorld(const WorldOptions& options);

}  // namespace mcslam::sim
