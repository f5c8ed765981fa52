// The conversions between Gazebo's ROS messages and the core's types (src/ros/conversions.h), no
// roscore: quaternions normalised as Gazebo does, an unset one the identity, non-finite input
// kept for the world to refuse, times in integer nanoseconds, names.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <gazebo_msgs/GetJointProperties.h>

#include "conversions.h"

namespace onedof_sim {
namespace {

geometry_msgs::Pose messagePose(double x, double y, double z, double qw, double qx, double qy,
                                double qz) {
  geometry_msgs::Pose p;
  p.position.x = x;
  p.position.y = y;
  p.position.z = z;
  p.orientation.w = qw;
  p.orientation.x = qx;
  p.orientation.y = qy;
  p.orientation.z = qz;
  return p;
}

TEST(Conversions, APosesQuaternionIsNormalisedAndAnUnsetOneIsTheIdentity) {
  const Pose scaled = toCore(messagePose(1, 2, 3, 0, 0, 0, 2));
  EXPECT_EQ(scaled.position.z, 3);
  EXPECT_EQ(scaled.orientation.w, 0);
  EXPECT_EQ(scaled.orientation.z, 1);
  const Pose unset = toCore(messagePose(0, 0, 0, 0, 0, 0, 0));
  EXPECT_EQ(unset.orientation.w, 1);
  EXPECT_EQ(unset.orientation.x, 0);
  const Pose half = toCore(messagePose(0, 0, 0, 1, 1, 1, 1));
  EXPECT_DOUBLE_EQ(half.orientation.w, 0.5);
  EXPECT_DOUBLE_EQ(half.orientation.y, 0.5);
  // Not finite: passed on as it is, for the world to refuse with NotFinite.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(std::isnan(toCore(messagePose(0, 0, 0, nan, 0, 0, 1)).orientation.w));
  EXPECT_TRUE(std::isnan(toCore(messagePose(nan, 0, 0, 1, 0, 0, 0)).position.x));
}

TEST(Conversions, RoundTripsVectorsPosesAndTwists) {
  const Pose pose{{1, -2, 3.5}, {0.5, 0.5, -0.5, 0.5}};
  const geometry_msgs::Pose m = toMsg(pose);
  EXPECT_EQ(m.position.y, -2);
  EXPECT_EQ(m.orientation.y, -0.5);
  const Pose back = toCore(m);
  EXPECT_EQ(back.position.x, 1);
  EXPECT_EQ(back.orientation.x, 0.5);
  const Twist twist{{1, 2, 3}, {-4, -5, -6}};
  const Twist twist_back = toCore(toMsg(twist));
  EXPECT_EQ(twist_back.linear.z, 3);
  EXPECT_EQ(twist_back.angular.x, -4);
  EXPECT_EQ(toCore(toVector3({7, 8, 9})).y, 8);
  EXPECT_EQ(toQuaternion({1, 0, 0, 0}).w, 1);
}

TEST(Conversions, TimesAreWholeNanoseconds) {
  EXPECT_EQ(toNs(ros::Time(4294967295u, 999999999u)), 4294967295999999999ll);
  EXPECT_EQ(toNs(ros::Duration(-2, 500000000)), -1500000000ll);
  EXPECT_EQ(toNs(ros::Time(0, 1)), 1);
}

TEST(Conversions, NamesAndJointTypes) {
  EXPECT_EQ(bareName("model::link"), "link");
  EXPECT_EQ(bareName("outer::inner::link"), "link");
  EXPECT_EQ(bareName("link"), "link");
  using Response = gazebo_msgs::GetJointProperties::Response;
  EXPECT_EQ(toJointTypeConstant(JointType::Revolute), Response::REVOLUTE);
  EXPECT_EQ(toJointTypeConstant(JointType::Continuous), Response::REVOLUTE);
  EXPECT_EQ(toJointTypeConstant(JointType::Prismatic), Response::PRISMATIC);
  EXPECT_EQ(toJointTypeConstant(JointType::Fixed), Response::FIXED);
}

}  // namespace
}  // namespace onedof_sim
