// Rigid-transform arithmetic on the public Vec3/Quat/Pose types: the one pose library of the
// core, the renderer's callers and the ROS layer. Quaternions are w first; the functions that
// take a rotation expect a unit quaternion.
#pragma once

#include <cmath>

#include "onedof_sim/world.h"

namespace onedof_sim {

inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator-(const Vec3& a) { return {-a.x, -a.y, -a.z}; }
inline Vec3 operator*(double s, const Vec3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// Without overflow: |(1e200, 0, 0)| is 1e200, where sqrt(dot) gives infinity.
inline double norm(const Vec3& a) { return std::hypot(a.x, a.y, a.z); }

// The Hamilton product a b: the turn b, then a.
inline Quat multiply(const Quat& a, const Quat& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
          a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
          a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}
inline Quat conjugate(const Quat& q) { return {q.w, -q.x, -q.y, -q.z}; }
inline double quatNorm(const Quat& q) {
  return std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
}
inline Quat normalized(const Quat& q) {
  const double n = quatNorm(q);
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}
// v turned by q.
inline Vec3 rotate(const Quat& q, const Vec3& v) {
  const Vec3 u{q.x, q.y, q.z};
  const Vec3 t = 2.0 * cross(u, v);
  return v + q.w * t + cross(u, t);
}
// v, given in the parent frame, in the axes of a frame turned by q.
inline Vec3 inFrame(const Quat& q, const Vec3& v) { return rotate(conjugate(q), v); }
inline Quat axisAngle(const Vec3& unit_axis, double angle) {
  const double s = std::sin(angle / 2);
  return {std::cos(angle / 2), s * unit_axis.x, s * unit_axis.y, s * unit_axis.z};
}
// Fixed-axis roll, pitch, yaw, as URDF (urdfdom's Rotation::setFromRPY), SDF and Gazebo
// (ignition::math::Quaternion(roll, pitch, yaw)) read a pose: about x, then the fixed y, then
// the fixed z, R = Rz(yaw) Ry(pitch) Rx(roll); their closed form, normalised as they normalise it.
inline Quat fromRpy(double roll, double pitch, double yaw) {
  const double cr = std::cos(roll / 2), sr = std::sin(roll / 2);
  const double cp = std::cos(pitch / 2), sp = std::sin(pitch / 2);
  const double cy = std::cos(yaw / 2), sy = std::sin(yaw / 2);
  return normalized({cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                     cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy});
}
inline Quat fromRpy(const Vec3& rpy) { return fromRpy(rpy.x, rpy.y, rpy.z); }

// The pose b, given in the frame a, in a's parent frame.
inline Pose compose(const Pose& a, const Pose& b) {
  return {a.position + rotate(a.orientation, b.position),
          normalized(multiply(a.orientation, b.orientation))};
}
inline Pose inverse(const Pose& a) {
  const Quat qi = conjugate(a.orientation);
  return {-rotate(qi, a.position), qi};
}
inline Vec3 transformPoint(const Pose& a, const Vec3& p) {
  return a.position + rotate(a.orientation, p);
}

// The rotation that takes +z to `normal` (a plane's <normal>); the identity for a zero normal.
inline Quat zTo(const Vec3& normal) {
  const double length = norm(normal);
  if (!(length > 0)) return {};
  const Vec3 n = (1.0 / length) * normal;
  const Vec3 z{0, 0, 1};
  if (dot(z, n) < -1 + 1e-12) return {0, 1, 0, 0};  // half a turn about x
  const Vec3 axis = cross(z, n);
  return normalized({1 + dot(z, n), axis.x, axis.y, axis.z});
}

inline bool isFinite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
inline bool isFinite(const Quat& q) {
  return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
}
inline bool isFinite(const Pose& p) { return isFinite(p.position) && isFinite(p.orientation); }

}  // namespace onedof_sim
