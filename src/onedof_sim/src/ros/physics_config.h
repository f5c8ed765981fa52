// dynamic_reconfigure as gazebo_ros serves it for the physics (set_parameters,
// parameter_descriptions, parameter_updates), with gazebo_ros' PhysicsConfig (cfg/Physics.cfg).
#pragma once

#include <dynamic_reconfigure/Config.h>
#include <dynamic_reconfigure/ConfigDescription.h>

#include <onedof_sim/world.h>

namespace onedof_sim {

// What the physics setters take: the world's parameters and the node's pace.
struct PhysicsSettings {
  PhysicsParams params;
  double max_update_rate = 0;
};

// The settings as a dynamic_reconfigure configuration.
dynamic_reconfigure::Config toConfig(const PhysicsSettings& settings);

// The fields a Reconfigure request names, set in *settings (clamped to each field's range, as
// dynamic_reconfigure's own servers clamp); the others keep their values.
void applyRequested(const dynamic_reconfigure::Config& request, PhysicsSettings* settings);

// The description (types, ranges, defaults) a dynamic_reconfigure client reads.
dynamic_reconfigure::ConfigDescription physicsDescription(const PhysicsSettings& defaults);

}  // namespace onedof_sim
