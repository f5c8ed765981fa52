// bench_bare_service: the floor of ROS for the simulator's services. It serves
// ~get_joint_properties and ~apply_joint_effort with the simulator's types and fixed replies
// (fixed_replies.h), so a round trip against it costs what ROS itself costs and nothing else.
//
//   rosrun onedof_sim bench_bare_service __name:=bare   ->  /bare/get_joint_properties, ...
#include <ros/ros.h>

#include "fixed_replies.h"

namespace {

bool applyJointEffort(gazebo_msgs::ApplyJointEffort::Request&,
                      gazebo_msgs::ApplyJointEffort::Response& res) {
  onedof_sim::bench::fixedEffortReply(&res);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "bare_service");
  ros::NodeHandle private_nh("~");
  const ros::ServiceServer get = private_nh.advertiseService(
      "get_joint_properties", onedof_sim::bench::fixedJointProperties);
  const ros::ServiceServer apply = private_nh.advertiseService("apply_joint_effort",
                                                               applyJointEffort);
  ros::spin();
  return 0;
}
