// The pose library (onedof_sim/pose_math.h), no ROS: roll-pitch-yaw read as URDF (urdfdom),
// SDF and Gazebo (ignition::math) read a pose, compose and inverse, and the frame turns.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <ignition/math/Quaternion.hh>
#include <urdf_model/pose.h>

#include "onedof_sim/pose_math.h"

namespace onedof_sim {
namespace {

const std::vector<double> kAngles{-3.1, -M_PI / 2, -1.0, -0.25, 0.0, 1e-9, 0.3, 1.2,
                                  M_PI / 2, 2.5, M_PI};

void expectNear(const Vec3& a, const Vec3& b, double tolerance) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

TEST(PoseMath, FromRpyIsIgnitionMathsQuaternionBitForBit) {
  for (double roll : kAngles)
    for (double pitch : kAngles)
      for (double yaw : kAngles) {
        const Quat q = fromRpy(roll, pitch, yaw);
        const ignition::math::Quaterniond gazebo(roll, pitch, yaw);
        EXPECT_EQ(q.w, gazebo.W()) << roll << " " << pitch << " " << yaw;
        EXPECT_EQ(q.x, gazebo.X()) << roll << " " << pitch << " " << yaw;
        EXPECT_EQ(q.y, gazebo.Y()) << roll << " " << pitch << " " << yaw;
        EXPECT_EQ(q.z, gazebo.Z()) << roll << " " << pitch << " " << yaw;
      }
}

TEST(PoseMath, FromRpyIsUrdfdomsRotation) {
  for (double roll : kAngles)
    for (double pitch : kAngles)
      for (double yaw : kAngles) {
        const Quat q = fromRpy(roll, pitch, yaw);
        urdf::Rotation urdf;
        urdf.setFromRPY(roll, pitch, yaw);
        // urdfdom sums the squares of its norm in another order: the last bit may differ.
        EXPECT_NEAR(q.w, urdf.w, 1e-15);
        EXPECT_NEAR(q.x, urdf.x, 1e-15);
        EXPECT_NEAR(q.y, urdf.y, 1e-15);
        EXPECT_NEAR(q.z, urdf.z, 1e-15);
      }
}

TEST(PoseMath, FromRpyTurnsAboutFixedXThenFixedYThenFixedZ) {
  for (double roll : kAngles)
    for (double pitch : kAngles)
      for (double yaw : kAngles) {
        const Quat q = fromRpy(roll, pitch, yaw);
        EXPECT_NEAR(quatNorm(q), 1.0, 1e-15);
        const Quat turns = multiply(axisAngle({0, 0, 1}, yaw),
                                    multiply(axisAngle({0, 1, 0}, pitch),
                                             axisAngle({1, 0, 0}, roll)));
        for (const Vec3& v : {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}, Vec3{0.3, -2, 5}})
          expectNear(rotate(q, v), rotate(turns, v), 1e-14);
      }
  // A quarter roll, then a quarter yaw about the fixed z: z goes to -y, then to +x (about moving
  // axes, x then y' then z'', it would end at -y).
  expectNear(rotate(fromRpy(M_PI / 2, 0, M_PI / 2), {0, 0, 1}), {1, 0, 0}, 1e-15);
  expectNear(rotate(fromRpy(Vec3{0, M_PI / 2, 0}), {1, 0, 0}), {0, 0, -1}, 1e-15);
}

TEST(PoseMath, ComposeInverseAndFrames) {
  const Pose a{{1, -2, 0.5}, fromRpy(0.3, -0.7, 2.0)};
  const Pose b{{-0.4, 0.1, 3}, fromRpy(-1.1, 0.2, 0.9)};
  const Pose ab = compose(a, b);
  expectNear(ab.position, transformPoint(a, b.position), 1e-15);
  EXPECT_NEAR(quatNorm(ab.orientation), 1.0, 1e-15);
  // a^-1 (a b) = b
  const Pose back = compose(inverse(a), ab);
  expectNear(back.position, b.position, 1e-14);
  const Vec3 v{0.2, 0.9, -1.3};
  expectNear(rotate(back.orientation, v), rotate(b.orientation, v), 1e-14);
  // inFrame undoes rotate.
  expectNear(inFrame(a.orientation, rotate(a.orientation, v)), v, 1e-15);
  expectNear(cross({1, 0, 0}, {0, 1, 0}), {0, 0, 1}, 0);
  EXPECT_EQ(norm({1e200, 0, 0}), 1e200);
  EXPECT_FALSE(isFinite(Pose{{0, NAN, 0}, {}}));
  EXPECT_TRUE(isFinite(a));
}

}  // namespace
}  // namespace onedof_sim
