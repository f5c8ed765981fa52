#include "ode_rays.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace onedof_sim {
namespace core {
namespace {

// Whether a closed primitive holds the point, inside or on its surface. A ray that starts there
// does not meet that shape, as Bullet's ray test does not and a GPU laser does not see the
// inside of a shape's faces: a lidar on a box link (the book's mobot's) starts every ray on its
// box's face, where ODE's ray-box test would give the face it leaves by, at distance 0.
bool holdsPoint(dGeomID geom, const dVector3 point) {
  constexpr double kOnSurface = 1e-9;  // m: a start computed onto a face lands within this
  switch (dGeomGetClass(geom)) {
    case dBoxClass:
      return dGeomBoxPointDepth(geom, point[0], point[1], point[2]) >= -kOnSurface;
    case dSphereClass:
      return dGeomSpherePointDepth(geom, point[0], point[1], point[2]) >= -kOnSurface;
    case dCapsuleClass:
      return dGeomCapsulePointDepth(geom, point[0], point[1], point[2]) >= -kOnSurface;
    case dCylinderClass: {
      dReal radius, length;
      dGeomCylinderGetParams(geom, &radius, &length);
      dVector3 local;  // the cylinder's axis is its z
      dGeomGetPosRelPoint(geom, point[0], point[1], point[2], local);
      return std::abs(local[2]) <= length / 2 + kOnSurface &&
             std::hypot(local[0], local[1]) <= radius + kOnSurface;
    }
    default:
      return false;
  }
}

}  // namespace

OdeRays::~OdeRays() {
  if (ray_) dGeomDestroy(ray_);  // in no space
}

void OdeRays::cast(dSpaceID space, const std::vector<Ray>& rays, std::vector<double>* distances) {
  distances->assign(rays.size(), std::numeric_limits<double>::infinity());
  if (!ray_) {
    ray_ = dCreateRay(nullptr, 1);
    dGeomRaySetFirstContact(ray_, 0);  // every hit, back faces too
    dGeomRaySetBackfaceCull(ray_, 0);
    dGeomRaySetClosestHit(ray_, 1);
  }
  for (size_t i = 0; i < rays.size(); ++i) {
    const Ray& ray = rays[i];
    if (!(ray.length > 0)) continue;
    dGeomRaySet(ray_, ray.from.x, ray.from.y, ray.from.z, ray.direction.x, ray.direction.y,
                ray.direction.z);
    dGeomRaySetLength(ray_, ray.length);
    hit_ = std::numeric_limits<double>::infinity();
    dSpaceCollide2(ray_, reinterpret_cast<dGeomID>(space), this, &collideRay);
    (*distances)[i] = hit_;
  }
}

void OdeRays::collideRay(void* data, dGeomID a, dGeomID b) {
  if (dGeomIsSpace(a) || dGeomIsSpace(b)) {
    dSpaceCollide2(a, b, data, &collideRay);
    return;
  }
  const dGeomID ray = dGeomGetClass(a) == dRayClass ? a : b;
  dVector3 start, direction;
  dGeomRayGet(ray, start, direction);
  if (holdsPoint(ray == a ? b : a, start)) return;
  dContactGeom contact;
  if (dCollide(a, b, 1, &contact, sizeof contact) > 0) {
    double& hit = static_cast<OdeRays*>(data)->hit_;
    hit = std::min(hit, static_cast<double>(contact.depth));
  }
}

}  // namespace core
}  // namespace onedof_sim
