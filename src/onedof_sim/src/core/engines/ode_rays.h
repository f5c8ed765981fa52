// Rays cast through ODE's collision detection against the geoms of an ODE space, as Gazebo's ODE
// ray sensor casts them: one dGeomRay, in no space, collided with the space (dSpaceCollide2, into
// the spaces inside it), then dCollide with the closest hit of each geom. The ODE engine casts
// against its world's space, the DART engine against the space of DART's ODE collision detector.
#pragma once

#include <ode/ode.h>

#include <vector>

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace core {

class OdeRays {
 public:
  OdeRays() = default;
  ~OdeRays();
  OdeRays(const OdeRays&) = delete;
  OdeRays& operator=(const OdeRays&) = delete;

  // For each ray, the distance to the first geom of `space` it meets, +infinity where none.
  // A closed primitive that holds the ray's start (inside or on its surface) is not met.
  void cast(dSpaceID space, const std::vector<Ray>& rays, std::vector<double>* distances);

 private:
  static void collideRay(void* data, dGeomID a, dGeomID b);

  dGeomID ray_ = nullptr;  // made at the first cast
  double hit_ = 0;         // the nearest hit of the ray being cast
};

}  // namespace core
}  // namespace onedof_sim
