// The contact rules every engine applies alike (src/core/engines/contact_rules.h), on geometry
// built here from a cylinder's pose: whether it lies, its line's ends and middle, the other end
// of a rocking cylinder's line, and when a contact slides.
#include <gtest/gtest.h>

#include <cmath>

#include "engines/contact_rules.h"
#include "onedof_sim/pose_math.h"

namespace onedof_sim {
namespace core {
namespace {

constexpr double kRadius = 0.05;
constexpr double kLength = 0.2;
const Vec3 kUp{0, 0, 1};

void expectNear(const Vec3& a, const Vec3& b, double tolerance) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

// The axis of a cylinder heading `yaw` about the vertical, its +end raised by `tilt` rad.
Vec3 axisOf(double yaw, double tilt) {
  return {std::cos(tilt) * std::cos(yaw), std::cos(tilt) * std::sin(yaw), std::sin(tilt)};
}

// The point of the cylinder's side line nearest the ground (z = 0) at `along` metres along the
// axis from its centre, as a contact with the ground: its depth is how far it is below z = 0.
TouchPoint linePoint(const Vec3& centre, const Vec3& axis, double along) {
  const Vec3 away = kUp - dot(axis, kUp) * axis;  // from the axis, away from the ground
  const Vec3 position = centre + along * axis - (kRadius / norm(away)) * away;
  return {position, kUp, -position.z};
}

TEST(ContactRules, ACylinderLiesWithinTenMilliradiansOfLevel) {
  EXPECT_TRUE(liesOn(axisOf(0.3, 0), kUp));
  EXPECT_TRUE(liesOn(axisOf(0.3, 0.0099), kUp));
  EXPECT_TRUE(liesOn(axisOf(0.3, -0.0099), kUp));
  EXPECT_FALSE(liesOn(axisOf(0.3, 0.0101), kUp));
  EXPECT_FALSE(liesOn(kUp, kUp));  // standing on an end face
}

TEST(ContactRules, TheEndsOfALyingCylindersLineAreTakenAsItsLine) {
  const Vec3 centre{1, 2, kRadius - 1e-4};
  const Vec3 axis = axisOf(0.7, 0.004);
  const TouchPoint p = linePoint(centre, axis, -kLength / 2);
  const TouchPoint q = linePoint(centre, axis, kLength / 2);
  EXPECT_TRUE(areLineEnds(axis, p, q));
  EXPECT_TRUE(areLineEnds(axis, q, p));

  const TouchPoint middle = pointOnLine(p, q, 0.5);
  expectNear(middle.position, linePoint(centre, axis, 0).position, 1e-15);
  EXPECT_NEAR(middle.depth, linePoint(centre, axis, 0).depth, 1e-15);
  expectNear(middle.normal, kUp, 0);
  const TouchPoint quarter = pointOnLine(p, q, 0.25);
  expectNear(quarter.position, linePoint(centre, axis, -kLength / 4).position, 1e-15);
  EXPECT_NEAR(quarter.depth, linePoint(centre, axis, -kLength / 4).depth, 1e-15);
}

TEST(ContactRules, PointsThatAreNotALyingLinesEndsAreLeftAlone) {
  const Vec3 centre{0, 0, kRadius};
  const Vec3 axis = axisOf(0, 0);
  const TouchPoint p = linePoint(centre, axis, -kLength / 2);
  const TouchPoint q = linePoint(centre, axis, kLength / 2);
  EXPECT_FALSE(areLineEnds(axisOf(0, 0.02), p, q));  // tilted past kLyingTilt
  EXPECT_FALSE(areLineEnds(axis, p, p));               // one point
  TouchPoint across = q;                               // the segment not along the axis
  across.position.y += 0.01;
  EXPECT_FALSE(areLineEnds(axis, p, across));
  TouchPoint turned = q;  // another face
  turned.normal = {0, std::sin(0.01), std::cos(0.01)};
  EXPECT_FALSE(areLineEnds(axis, p, turned));
}

TEST(ContactRules, ARockingCylindersLowerRimGetsItsLinesOtherEnd) {
  // The +end raised 3 mrad: the -end's rim touches 0.1 mm deep, the +end's is 0.5 mm clear.
  const Vec3 axis = axisOf(-1.1, 0.003);
  Vec3 centre{0.5, -0.2, 0};
  centre.z = -linePoint(centre, axis, -kLength / 2).position.z - 1e-4;
  const TouchPoint rim = linePoint(centre, axis, -kLength / 2);
  const TouchPoint expected = linePoint(centre, axis, kLength / 2);
  ASSERT_NEAR(rim.depth, 1e-4, 1e-15);
  TouchPoint other;
  ASSERT_TRUE(otherLineEnd(centre, axis, kLength, kUp, rim, &other));
  expectNear(other.position, expected.position, 1e-15);
  EXPECT_NEAR(other.depth, expected.depth, 1e-15);
  EXPECT_LT(other.depth, 0);
  EXPECT_TRUE(areLineEnds(axis, rim, other));

  EXPECT_FALSE(otherLineEnd(centre, axis, kLength, kUp, linePoint(centre, axis, 0), &other));
  EXPECT_FALSE(otherLineEnd(centre, axisOf(-1.1, 0.02), kLength, kUp, rim, &other));
}

TEST(ContactRules, ALyingCylindersLineMiddleIsItsLowestPointHalfWay) {
  for (double tilt : {0.0, 0.008, -0.008}) {
    const Vec3 axis = axisOf(2.0, tilt);
    const Vec3 centre{-3, 4, kRadius};
    expectNear(lineMiddle(centre, axis, kRadius, kUp), linePoint(centre, axis, 0).position, 1e-15);
  }
  expectNear(lineMiddle({1, 2, kRadius}, {1, 0, 0}, kRadius, kUp), {1, 2, 0}, 0);
}

TEST(ContactRules, TheAxisInTheContactPlaneIsUnitAndLevel) {
  const Vec3 in_plane = axisInPlane(axisOf(0.4, 0.009), kUp);
  EXPECT_NEAR(norm(in_plane), 1, 1e-15);
  EXPECT_NEAR(dot(in_plane, kUp), 0, 1e-15);
  expectNear(in_plane, axisOf(0.4, 0), 1e-15);
}

TEST(ContactRules, AContactSlidesFasterThanTheSlidingSpeedInItsPlane) {
  Vec3 slip;
  ASSERT_TRUE(slides({0.03, -0.04, 7}, kUp, &slip));  // the normal part left out
  expectNear(slip, {0.03, -0.04, 0}, 1e-15);
  EXPECT_FALSE(slides({0.006, 0.0079, 7}, kUp, &slip));  // under 0.01 m/s
  EXPECT_FALSE(slides({0, 0, -3}, kUp, &slip));
  const Vec3 tilted{0, std::sin(0.5), std::cos(0.5)};
  ASSERT_TRUE(slides({0, 0.02, 0}, tilted, &slip));  // 0.0175 m/s of it in the plane
  expectNear(slip, 0.02 * std::cos(0.5) * Vec3{0, std::cos(0.5), -std::sin(0.5)}, 1e-15);
  EXPECT_FALSE(slides({0, 0.011, 0}, tilted, &slip));  // 0.0097 m/s of it in the plane
}

}  // namespace
}  // namespace core
}  // namespace onedof_sim
