// Vectors, rotations and poses between the core's types and Bullet's. Private to the core.
#pragma once

#include <LinearMath/btTransform.h>

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace core {

inline btVector3 toBt(const Vec3& v) { return {v.x, v.y, v.z}; }
inline btQuaternion toBt(const Quat& q) { return {q.x, q.y, q.z, q.w}; }
inline btTransform toBt(const Pose& p) {
  return btTransform(toBt(p.orientation), toBt(p.position));
}
inline Vec3 fromBt(const btVector3& v) { return {v.x(), v.y(), v.z()}; }
inline Quat fromBt(const btQuaternion& q) { return {q.w(), q.x(), q.y(), q.z()}; }
inline Pose fromBt(const btTransform& t) {
  return {fromBt(t.getOrigin()), fromBt(t.getRotation())};
}

}  // namespace core
}  // namespace onedof_sim
