// bench_bare_service: the floor of ROS for the simulator's services. It serves
// ~get_joint_properties and ~apply_joint_effort with the simulator's types and fixed replies of
// the same size as the simulator's (one position, one rate, the same status texts), so a round
// trip against it costs what ROS itself costs and nothing else.
//
//   rosrun onedof_sim bench_bare_service __name:=bare   ->  /bare/get_joint_properties, ...
#include <ros/ros.h>

#include <gazebo_msgs/ApplyJointEffort.h>
#include <gazebo_msgs/GetJointProperties.h>

namespace {

bool getJointProperties(gazebo_msgs::GetJointProperties::Request&,
                        gazebo_msgs::GetJointProperties::Response& res) {
  res.type = gazebo_msgs::GetJointProperties::Response::REVOLUTE;
  res.position = {0.0};
  res.rate = {0.0};
  res.success = true;
  res.status_message = "GetJointProperties: got properties";
  return true;
}

bool applyJointEffort(gazebo_msgs::ApplyJointEffort::Request&,
                      gazebo_msgs::ApplyJointEffort::Response& res) {
  res.success = true;
  res.status_message = "ApplyJointEffort: effort set";
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "bare_service");
  ros::NodeHandle private_nh("~");
  const ros::ServiceServer get = private_nh.advertiseService("get_joint_properties",
                                                             getJointProperties);
  const ros::ServiceServer apply = private_nh.advertiseService("apply_joint_effort",
                                                               applyJointEffort);
  ros::spin();
  return 0;
}
