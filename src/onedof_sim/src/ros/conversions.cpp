#include "conversions.h"

#include <cmath>
#include <string>
#include <vector>

#include <gazebo_msgs/GetJointProperties.h>
#include <onedof_sim/pose_math.h>

namespace onedof_sim {
Vec3 toCore(const geometry_msgs::Vector3& v) { return {v.x, v.y, v.z}; }
Vec3 toCore(const geometry_msgs::Point& p) { return {p.x, p.y, p.z}; }

Pose toCore(const geometry_msgs::Pose& p) {
  Pose pose;
  pose.position = toCore(p.position);
  const Quat q{p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z};
  // A zero quaternion stays the identity; a NaN one, or one whose norm overflows, goes through
  // as it is, for the core to refuse.
  const double norm = quatNorm(q);
  if (std::isfinite(norm) && norm > 1e-12) pose.orientation = normalized(q);
  else if (!(norm <= 1e-12)) pose.orientation = q;
  return pose;
}

Twist toCore(const geometry_msgs::Twist& t) { return {toCore(t.linear), toCore(t.angular)}; }

geometry_msgs::Vector3 toVector3(const Vec3& v) {
  geometry_msgs::Vector3 m;
  m.x = v.x;
  m.y = v.y;
  m.z = v.z;
  return m;
}

geometry_msgs::Quaternion toQuaternion(const Quat& q) {
  geometry_msgs::Quaternion m;
  m.w = q.w;
  m.x = q.x;
  m.y = q.y;
  m.z = q.z;
  return m;
}

geometry_msgs::Pose toMsg(const Pose& p) {
  geometry_msgs::Pose m;
  m.position.x = p.position.x;
  m.position.y = p.position.y;
  m.position.z = p.position.z;
  m.orientation = toQuaternion(p.orientation);
  return m;
}

geometry_msgs::Twist toMsg(const Twist& t) {
  geometry_msgs::Twist m;
  m.linear = toVector3(t.linear);
  m.angular = toVector3(t.angular);
  return m;
}

int64_t toNs(const ros::Time& t) { return int64_t(t.sec) * kNsPerS + int64_t(t.nsec); }
int64_t toNs(const ros::Duration& d) { return int64_t(d.sec) * kNsPerS + int64_t(d.nsec); }

std::string bareName(const std::string& scoped) {
  const auto pos = scoped.rfind("::");
  return pos == std::string::npos ? scoped : scoped.substr(pos + 2);
}

uint8_t toJointTypeConstant(JointType type) {
  switch (type) {
    case JointType::Prismatic:
      return gazebo_msgs::GetJointProperties::Response::PRISMATIC;
    case JointType::Fixed:
      return gazebo_msgs::GetJointProperties::Response::FIXED;
    case JointType::Revolute:
    case JointType::Continuous:
      break;
  }
  return gazebo_msgs::GetJointProperties::Response::REVOLUTE;
}

namespace {

// Each named model's or link's pose and twist, of those `read` finds, in the names' order.
template <class Message, class Read>
Message statesOf(const std::vector<std::string>& names, Read read) {
  Message states;
  for (const auto& name : names) {
    Pose pose;
    Twist twist;
    if (!read(name, &pose, &twist).ok()) continue;
    states.name.push_back(name);
    states.pose.push_back(toMsg(pose));
    states.twist.push_back(toMsg(twist));
  }
  return states;
}

}  // namespace

gazebo_msgs::ModelStates modelStatesOf(const World& world) {
  return statesOf<gazebo_msgs::ModelStates>(
      world.modelNames(), [&world](const std::string& name, Pose* pose, Twist* twist) {
        return world.modelState(name, "", pose, twist);
      });
}

gazebo_msgs::LinkStates linkStatesOf(const World& world) {
  return statesOf<gazebo_msgs::LinkStates>(
      world.linkNames(), [&world](const std::string& name, Pose* pose, Twist* twist) {
        return world.linkState(name, "", pose, twist);
      });
}

}  // namespace onedof_sim
