// The quaternion arithmetic the plugins' offsets and sensor frames need (the core's pose
// arithmetic is private to it). Quaternions are unit, w first.
#pragma once

#include <cmath>

#include <onedof_sim/world.h>

namespace onedof_sim::plugins {

inline Quat product(const Quat& a, const Quat& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

// Fixed-axis roll, pitch, yaw: Rz(yaw) Ry(pitch) Rx(roll).
inline Quat fromRpy(const Vec3& rpy) {
  const double cr = std::cos(rpy.x / 2), sr = std::sin(rpy.x / 2);
  const double cp = std::cos(rpy.y / 2), sp = std::sin(rpy.y / 2);
  const double cy = std::cos(rpy.z / 2), sy = std::sin(rpy.z / 2);
  return {cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
          cr * cp * sy - sr * sp * cy};
}

inline Quat normalized(const Quat& q) {
  const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}

// v, given in the world, in the axes of a frame turned by q.
inline Vec3 inFrame(const Quat& q, const Vec3& v) {
  const Quat back{q.w, -q.x, -q.y, -q.z};
  const Quat turned = product(product(back, {0, v.x, v.y, v.z}), q);
  return {turned.x, turned.y, turned.z};
}

}  // namespace onedof_sim::plugins
