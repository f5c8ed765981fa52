// Rays through the MuJoCo engine's shapes as they stand (mujoco_engine.cpp's castRays), through
// MuJoCo's own ray functions. Private to the core.
#pragma once

#include <mujoco/mujoco.h>

#include <vector>

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace core {
namespace mujoco_rays {

// Each ray's distance to the first geom it meets, +infinity where it meets none (Engine::castRays),
// with d's geom poses (mj_kinematics done).
void cast(const mjModel* m, const mjData* d, const std::vector<Ray>& rays,
          std::vector<double>* distances);

}  // namespace mujoco_rays
}  // namespace core
}  // namespace onedof_sim
