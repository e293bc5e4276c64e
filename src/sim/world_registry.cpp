#include "mcslam/core/error.hpp"
#include "world_named.hpp"

namespace mcslam::sim {

std::vector<std::string> worldNames() { return {"indoor", "corridor", "courtyard"}; }

std::string describeWorlds() {
  return "  indoor     four furnished rooms (office, storage, lounge, meeting) joined by corridors into a ring;\n"
         "             ground loop of about 75 m with four turns and two stops\n"
         "  corridor   a 44 m long, 2.4 m wide corridor with bare, poorly textured stretches, halls at both ends;\n"
         "             the loop goes down one side and back the other (about 100 m)\n"
         "  courtyard  outdoor square between building facades 15-40 m away, trees, benches, lamps; sun and sky;\n"
         "             loop of about 80 m\n";
}

std::shared_ptr<const World> makeWorld(const std::string& name, const WorldOptions& options) {
  if (name == "indoor") return buildIndoorWorld(options);
  if (name == "corridor") return buildCorridorWorld(options);
  if (name == "courtyard") return buildCourtyardWorld(options);
  throw InputError("unknown world '" + name + "' (worlds: indoor, corridor, courtyard)");
}

}  // namespace mcslam::sim
