#include "mujoco_rays.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "onedof_sim/pose_math.h"

namespace onedof_sim {
namespace core {
namespace mujoco_rays {
namespace {

// Whether a closed primitive holds the point (inside or on its surface): a ray that starts there
// does not meet it, as with the other engines (a lidar on a box link starts on its face).
bool holdsPoint(const mjModel* m, const mjData* d, int geom, const mjtNum* point) {
  constexpr double kOnSurface = 1e-9;
  const mjtNum* pos = d->geom_xpos + 3 * geom;
  const mjtNum* mat = d->geom_xmat + 9 * geom;
  const mjtNum* size = m->geom_size + 3 * geom;
  mjtNum local[3];
  for (int r = 0; r < 3; ++r)
    local[r] = mat[r] * (point[0] - pos[0]) + mat[3 + r] * (point[1] - pos[1]) +
               mat[6 + r] * (point[2] - pos[2]);
  switch (m->geom_type[geom]) {
    case mjGEOM_BOX:
      return std::fabs(local[0]) <= size[0] + kOnSurface &&
             std::fabs(local[1]) <= size[1] + kOnSurface &&
             std::fabs(local[2]) <= size[2] + kOnSurface;
    case mjGEOM_SPHERE: return std::hypot(local[0], local[1], local[2]) <= size[0] + kOnSurface;
    case mjGEOM_CYLINDER:
      return std::fabs(local[2]) <= size[1] + kOnSurface &&
             std::hypot(local[0], local[1]) <= size[0] + kOnSurface;
    default: return false;
  }
}

// Each ray against every shape (mju_rayGeom, mj_rayMesh on a mesh's hull) whose bounding sphere
// it reaches, a plane always.
}  // namespace

void cast(const mjModel* m, const mjData* d, const std::vector<Ray>& rays,
          std::vector<double>* distances) {
  distances->assign(rays.size(), std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < rays.size(); ++i) {
    const Ray& ray = rays[i];
    if (!(ray.length > 0)) continue;
    const mjtNum from[3] = {ray.from.x, ray.from.y, ray.from.z};
    const mjtNum direction[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
    double nearest = std::numeric_limits<double>::infinity();
    for (int g = 0; g < m->ngeom; ++g) {
      const mjtNum* centre = d->geom_xpos + 3 * g;
      const int type = m->geom_type[g];
      if (type != mjGEOM_PLANE) {
        const Vec3 offset = {centre[0] - from[0], centre[1] - from[1], centre[2] - from[2]};
        const double along = std::clamp(dot(offset, ray.direction), 0.0, ray.length);
        if (norm(offset - along * ray.direction) > m->geom_rbound[g]) continue;
      }
      if (holdsPoint(m, d, g, from)) continue;
      const double hit =
          type == mjGEOM_MESH
              ? mj_rayMesh(m, d, g, from, direction)
              : mju_rayGeom(centre, d->geom_xmat + 9 * g, m->geom_size + 3 * g, from,
                            direction, type);
      if (hit >= 0 && hit <= ray.length) nearest = std::min(nearest, hit);
    }
    (*distances)[i] = nearest;
  }
}

}  // namespace mujoco_rays
}  // namespace core
}  // namespace onedof_sim
