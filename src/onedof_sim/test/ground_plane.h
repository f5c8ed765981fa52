// Gazebo's ground for the gtests that build a World directly: a World is empty, and its ground is
// the package's ground_plane model (models/ground_plane, the one worlds/empty.world places),
// spawned at the origin as a world file places it.
#pragma once

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

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

// The ground plane read into a model, for a test that spawns it into many Worlds: libsdformat
// takes tens of milliseconds to read any SDF (it loads its own schema each time), more than such
// a test's World steps for, so it is read once (a forked child spawns its own copy).
inline PreparedModel preparedGroundPlane() {
  PreparedModel prepared = World::prepare(groundPlaneSdf(), ModelFormat::Sdf, {});
  if (!prepared.status().ok())
    throw std::runtime_error("the ground plane is no model: " + prepared.status().subject);
  return prepared;
}

// Spawns the ground plane into `world` (first, as a world file's include places it).
inline void addGroundPlane(World& world, PreparedModel ground) {
  const Status status = world.spawn("ground_plane", std::move(ground), Pose());
  if (!status.ok()) throw std::runtime_error("the ground plane did not spawn: " + status.subject);
}

inline void addGroundPlane(World& world) { addGroundPlane(world, preparedGroundPlane()); }

}  // namespace onedof_sim::testing_support
