// The contact rules every engine applies alike to what its own collision and solver give: where
// a cylinder lying on a face carries its load and friction, and when a contact slides. Geometry
// only, in world coordinates: each engine reads its contact points into these and writes the
// results back into its own contact records. No engine library and no ROS here.
//
// A cylinder lying on a face touches it along a line (its side line nearest the face). Collision
// gives that line's two end points on the rims (ODE's, and DART's through ODE's collider;
// MuJoCo's), or one deepest point a step (Bullet's convex-plane pair). Resolved as two points with
// friction, the ends resist the cylinder turning about the normal (a caster wheel swivelling,
// with up to mu N w / 2 for a line w long), and how the rigid line's load splits between them is
// indeterminate: the solver loads either, the point that grips sets a wheel's track, and a
// two-wheeled base's turn rate with it. Every engine resolves the line by its resultant instead:
// one point at the line's middle carrying the line's load and friction, so that a wheel's track
// is its middle's and no friction torque about the normal holds a caster from swivelling (the
// book's mobot's 8 cm casters, held by an evenly loaded line's mu N w / 4, pin it against its
// 5 N m wheel motors; a real caster's crowned tyre scrubs far less). What steadies the cylinder
// about the middle is the engine's own (ode_engine.cpp, mujoco_engine.cpp: frictionless soft
// supports at other points of the line).
#pragma once

#include "onedof_sim/world.h"

namespace onedof_sim {
namespace core {

// A cylinder lies on a face when its axis is square to the face's normal within this (the sine
// of the angle between them): 10 mrad, 0.7 mm of height over the book's 7 cm wheel. Beyond it only
// one rim touches, and the engine's own collision stands.
constexpr double kLyingTilt = 0.01;

// Friction at a contact whose bodies slide over each other, at the step's start, faster than
// this (m/s) is Coulomb's: mu times the normal force, against the slip, whatever its direction.
// Slower, each engine's friction pyramid holds the contact, its directions fixed in the contact
// plane: a pyramid on a sliding contact brakes the slip along one of its directions only and
// holds it across the other, so that a caster dragged at an angle to it pins its base sideways.
constexpr double kSlidingSpeed = 0.01;

// A point where two shapes touch, as an engine's collision gives it.
struct TouchPoint {
  Vec3 position;
  Vec3 normal;  // unit
  double depth = 0;  // overlap along the normal, m (negative: apart)
};

// Whether a cylinder whose axis is `axis` (unit) lies on a face whose normal is `normal`: the
// axis square to the normal within kLyingTilt.
bool liesOn(const Vec3& axis, const Vec3& normal);

// Whether `p` and `q` are the two ends of the side line along which a cylinder (axis `axis`,
// unit) lies on a face: the same normal, the cylinder lying on it, and the segment between them,
// not empty, along the axis.
bool areLineEnds(const Vec3& axis, const TouchPoint& p, const TouchPoint& q);

// The point at `fraction` of the way from `p` to `q` (0.5: the line's middle), at the depth
// interpolated likewise, with p's normal.
TouchPoint pointOnLine(const TouchPoint& p, const TouchPoint& q, double fraction);

// A cylinder (centre, axis unit, length) lying within kLyingTilt with one rim a little higher than
// the other touches with the lower rim's point `rim` alone. Sets *other to the other end of the
// side line through it, at that end's depth (negative when it is clear of the face), so that the
// two are taken as a lying cylinder's line ends: the contact does not jump from the line to a rim
// and back as the cylinder rocks by microradians. `into_cylinder` is the unit normal pointing out
// of the face towards the cylinder. False when `rim` is not on a rim or the cylinder does not lie.
bool otherLineEnd(const Vec3& centre, const Vec3& axis, double length, const Vec3& into_cylinder,
                  const TouchPoint& rim, TouchPoint* other);

// The middle of the side line of a cylinder (centre, axis unit, radius) lying on a face whose
// normal `normal` points out of the face towards it: the cylinder's point nearest the face, half
// way along.
Vec3 lineMiddle(const Vec3& centre, const Vec3& axis, double radius, const Vec3& normal);

// The cylinder's axis projected into the contact plane, unit: the rolling direction's square, the
// friction direction along which a wheel slides sideways.
Vec3 axisInPlane(const Vec3& axis, const Vec3& normal);

// Whether a contact slides: `relative_velocity` is one body's material point velocity at the
// contact less the other's. Sets *slip to its part in the contact plane (that body's way) and
// returns true when that is faster than kSlidingSpeed; the engine takes the slip's direction
// with its own vector arithmetic.
bool slides(const Vec3& relative_velocity, const Vec3& normal, Vec3* slip);

}  // namespace core
}  // namespace onedof_sim
