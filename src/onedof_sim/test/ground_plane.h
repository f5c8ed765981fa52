// Gazebo's ground for the gtests that build a World directly: a World is empty, and its ground is
// the package's ground_plane model (models/ground_plane, the one worlds/empty.world places),
// spawned at the origin as a world file places it.
#pragma once

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "onedof_sim/world.h"

namespace onedof_sim::testing_support {

// The ground plane's collision in contacts, as Gazebo's ground_plane model names it.
constexpr const char* kGroundCollision = "ground_plane::link::collision";

inline std::string groundPlaneSdf() {
  std::ifstream file(ONEDOF_SOURCE_DIR "/src/onedof_sim/models/ground_plane/model.sdf");
  if (!file) throw std::runtime_error("the package's models/ground_plane/model.sdf is not there");
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// Spawns the ground plane into `world` (first, as a world file's include places it).
inline void addGroundPlane(World& world) {
  const Status status = world.spawn("ground_plane", groundPlaneSdf(), ModelFormat::Sdf, Pose());
  if (!status.ok()) throw std::runtime_error("the ground plane did not spawn: " + status.subject);
}

}  // namespace onedof_sim::testing_support
