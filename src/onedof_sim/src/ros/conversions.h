// Conversions between the ROS messages of Gazebo's API and the core's types.
#pragma once

#include <cstdint>
#include <string>

#include <gazebo_msgs/LinkStates.h>
#include <gazebo_msgs/ModelStates.h>
#include <geometry_msgs/Point.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Twist.h>
#include <geometry_msgs/Vector3.h>
#include <ros/time.h>

#include <onedof_sim/world.h>

namespace onedof_sim {

constexpr int64_t kNsPerS = 1000000000;

Vec3 toCore(const geometry_msgs::Vector3& v);
Vec3 toCore(const geometry_msgs::Point& p);
// Normalises the quaternion as Gazebo does; an all-zero one (an unset message field) is the
// identity, so World's ZeroQuaternion never reaches a ROS caller. A non-finite one, or one whose
// norm overflows, stays as it is, for the world to refuse (NotFinite, QuaternionOverflow).
Pose toCore(const geometry_msgs::Pose& p);
Twist toCore(const geometry_msgs::Twist& t);

geometry_msgs::Vector3 toVector3(const Vec3& v);
geometry_msgs::Quaternion toQuaternion(const Quat& q);
geometry_msgs::Pose toMsg(const Pose& p);
geometry_msgs::Twist toMsg(const Twist& t);

// Every model's (link's) pose and twist in the world frame, as /gazebo/model_states
// (/gazebo/link_states) publishes them; world locked.
gazebo_msgs::ModelStates modelStatesOf(const World& world);
gazebo_msgs::LinkStates linkStatesOf(const World& world);

// ROS time and duration to nanoseconds; sec/nsec are widened first so nothing overflows.
int64_t toNs(const ros::Time& t);
int64_t toNs(const ros::Duration& d);

// "model::link" -> "link".
std::string bareName(const std::string& scoped);

// gazebo_msgs/GetJointProperties' type constant for a joint type.
uint8_t toJointTypeConstant(JointType type);

}  // namespace onedof_sim
