// The benchmark's stand-ins for the simulator's get_joint_properties and apply_joint_effort: fixed
// replies of the same size as the simulator's (one position, one rate, the same status texts), so
// a round trip against them costs what ROS itself costs and nothing else.
#pragma once

#include <gazebo_msgs/ApplyJointEffort.h>
#include <gazebo_msgs/GetJointProperties.h>

namespace onedof_sim::bench {

inline bool fixedJointProperties(gazebo_msgs::GetJointProperties::Request&,
                                 gazebo_msgs::GetJointProperties::Response& res) {
  res.type = gazebo_msgs::GetJointProperties::Response::REVOLUTE;
  res.position = {0.0};
  res.rate = {0.0};
  res.success = true;
  res.status_message = "GetJointProperties: got properties";
  return true;
}

inline void fixedEffortReply(gazebo_msgs::ApplyJointEffort::Response* res) {
  res->success = true;
  res->status_message = "ApplyJointEffort: effort set";
}

}  // namespace onedof_sim::bench
