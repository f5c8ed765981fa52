#include "conversions.h"

#include <cmath>

#include <gazebo_msgs/GetJointProperties.h>
#include <onedof_sim/pose_math.h>

namespace onedof_sim {
namespace {

constexpr double kGroundMarkerSize = 10.0;  // m, the plane drawn as a thin square

}  // namespace

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

visualization_msgs::Marker toMarker(const CollisionShape& shape, int id) {
  visualization_msgs::Marker marker;
  marker.header.frame_id = "world";
  // One namespace per model: one checkbox per model in rviz's MarkerArray display, so our rviz
  // view shows the world (the table) and leaves the robot, which its RobotModel already draws,
  // off until asked for.
  marker.ns = shape.model;
  marker.id = id;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose = toMsg(shape.pose);
  marker.color.r = marker.color.g = marker.color.b = 0.6f;
  marker.color.a = 0.8f;
  switch (shape.shape) {
    case GeometryShape::Box:
      marker.type = visualization_msgs::Marker::CUBE;
      marker.scale = toVector3(shape.size);
      break;
    case GeometryShape::Cylinder:
      marker.type = visualization_msgs::Marker::CYLINDER;
      marker.scale.x = marker.scale.y = 2 * shape.size.x;
      marker.scale.z = shape.size.z;
      break;
    case GeometryShape::Sphere:
      marker.type = visualization_msgs::Marker::SPHERE;
      marker.scale.x = marker.scale.y = marker.scale.z = 2 * shape.size.x;
      break;
    case GeometryShape::Mesh:
      marker.type = visualization_msgs::Marker::MESH_RESOURCE;
      marker.mesh_resource = "file://" + shape.mesh_file;
      marker.scale = toVector3(shape.size);
      break;
    case GeometryShape::Plane:
      marker.type = visualization_msgs::Marker::CUBE;
      marker.scale.x = marker.scale.y = kGroundMarkerSize;
      marker.scale.z = 0.001;
      marker.color.a = 0.3f;
      break;
  }
  return marker;
}

}  // namespace onedof_sim
