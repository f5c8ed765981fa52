#include "contact_rules.h"

#include <cmath>

#include "onedof_sim/pose_math.h"

namespace onedof_sim {
namespace core {
namespace {

// Two contact normals are the same within this (1 less the cosine between them), and a segment
// lies along an axis within this (1 less the cosine).
constexpr double kSameNormal = 1e-9;
constexpr double kAlongAxis = 1e-6;

double length(const Vec3& v) { return std::sqrt(dot(v, v)); }

}  // namespace

bool liesOn(const Vec3& axis, const Vec3& normal) {
  return std::fabs(dot(axis, normal)) <= kLyingTilt;
}

bool areLineEnds(const Vec3& axis, const TouchPoint& p, const TouchPoint& q) {
  const Vec3 segment = q.position - p.position;
  const double segment_length = length(segment);
  return dot(p.normal, q.normal) >= 1 - kSameNormal && liesOn(axis, p.normal) &&
         segment_length != 0 && std::fabs(dot(segment, axis)) >= segment_length * (1 - kAlongAxis);
}

TouchPoint pointOnLine(const TouchPoint& p, const TouchPoint& q, double fraction) {
  TouchPoint point = p;
  point.position = p.position + fraction * (q.position - p.position);
  point.depth = p.depth + fraction * (q.depth - p.depth);
  return point;
}

bool otherLineEnd(const Vec3& centre, const Vec3& axis, double length, const Vec3& into_cylinder,
                  const TouchPoint& rim, TouchPoint* other) {
  const double along = dot(rim.position - centre, axis);
  if (!liesOn(axis, into_cylinder) || std::fabs(along) < length / 2 * (1 - kAlongAxis))
    return false;
  *other = rim;
  other->position = rim.position - (2 * along) * axis;
  // Going along the line from the lower rim to the higher one rises by -2 along (axis . normal).
  other->depth = rim.depth + 2 * along * dot(axis, into_cylinder);
  return true;
}

Vec3 lineMiddle(const Vec3& centre, const Vec3& axis, double radius, const Vec3& normal) {
  const Vec3 across = normal - dot(axis, normal) * axis;  // from the axis away from the face
  const Vec3 down = -((1 / length(across)) * across);
  return centre + radius * down;
}

Vec3 axisInPlane(const Vec3& axis, const Vec3& normal) {
  const Vec3 in_plane = axis - dot(axis, normal) * normal;
  const double norm = length(in_plane);
  return {in_plane.x / norm, in_plane.y / norm, in_plane.z / norm};
}

bool slides(const Vec3& relative_velocity, const Vec3& normal, Vec3* slip) {
  *slip = relative_velocity - dot(relative_velocity, normal) * normal;
  return length(*slip) > kSlidingSpeed;
}

}  // namespace core
}  // namespace onedof_sim
