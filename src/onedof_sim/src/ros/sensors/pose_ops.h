// The pose arithmetic the plugins need (the core's is private to it): quaternion products,
// fixed-axis roll-pitch-yaw, rotating a vector into and out of a frame and composing poses.
// Quaternions are unit, w first.
#pragma once

#include <cmath>

#include <onedof_sim/world.h>

namespace onedof_sim::plugins {

inline Quat product(const Quat& a, const Quat& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
          a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
          a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

// Fixed-axis roll, pitch, yaw: Rz(yaw) Ry(pitch) Rx(roll).
inline Quat fromRpy(const Vec3& rpy) {
  const double cr = std::cos(rpy.x / 2), sr = std::sin(rpy.x / 2);
  const double cp = std::cos(rpy.y / 2), sp = std::sin(rpy.y / 2);
  const double cy = std::cos(rpy.z / 2), sy = std::sin(rpy.z / 2);
  return {cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
          cr * cp * sy - sr * sp * cy};
}

// v turned by the unit quaternion q.
inline Vec3 rotate(const Quat& q, const Vec3& v) {
  // t = 2 (q.xyz x v); v + w t + q.xyz x t
  const double tx = 2 * (q.y * v.z - q.z * v.y), ty = 2 * (q.z * v.x - q.x * v.z),
               tz = 2 * (q.x * v.y - q.y * v.x);
  return {v.x + q.w * tx + (q.y * tz - q.z * ty), v.y + q.w * ty + (q.z * tx - q.x * tz),
          v.z + q.w * tz + (q.x * ty - q.y * tx)};
}

// v, given in the world, in the axes of a frame turned by the unit quaternion q.
inline Vec3 inFrame(const Quat& q, const Vec3& v) { return rotate({q.w, -q.x, -q.y, -q.z}, v); }

inline Quat normalized(const Quat& q) {
  const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}

// The pose `b`, given in the frame `a`, in a's parent frame.
inline Pose compose(const Pose& a, const Pose& b) {
  const Vec3 moved = rotate(a.orientation, b.position);
  return {{a.position.x + moved.x, a.position.y + moved.y, a.position.z + moved.z},
          product(a.orientation, b.orientation)};
}

}  // namespace onedof_sim::plugins
