// Ray queries against the world's collision shapes (World::castRays), answered by the engine's
// own collision detection.
#include <cmath>
#include <string>
#include <vector>

#include "world_impl.h"

namespace onedof_sim {

using namespace core;

Status World::castRays(const std::vector<Ray>& rays, std::vector<double>* distances) {
  distances->clear();
  std::vector<Ray> unit(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) {
    const Ray& ray = rays[i];
    if (!isFinite(ray.from) || !isFinite(ray.direction) || !std::isfinite(ray.length))
      return {StatusCode::NotFinite, "ray"};
    const double norm = std::sqrt(ray.direction.x * ray.direction.x +
                                  ray.direction.y * ray.direction.y +
                                  ray.direction.z * ray.direction.z);
    if (!(norm > 0) || ray.length < 0 || !withinPosition(ray.from))
      return {StatusCode::InvalidParameter, "ray"};
    unit[i] = {ray.from,
               {ray.direction.x / norm, ray.direction.y / norm, ray.direction.z / norm},
               ray.length};
  }
  try {
    impl_->engine->castRays(unit, distances);
  } catch (const EngineFault& fault) {
    distances->clear();
    // The bodies are where the query found them: read them from the failed engine.
    impl_->saveStates();
    impl_->rebuildEngine(impl_->saved_states);
    impl_->warn(std::string("a ray query failed inside the physics engine (") + fault.what() +
                "): the engine was rebuilt with every model where it was");
    return {StatusCode::EngineFault, fault.what()};
  }
  return {};
}

}  // namespace onedof_sim
