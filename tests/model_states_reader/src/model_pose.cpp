// Prints the position of the model named on the command line, from the first
// /gazebo/model_states that has it, and exits: `position x y z`.
#include <gazebo_msgs/ModelStates.h>
#include <ros/ros.h>

#include <cstdio>
#include <string>

namespace {
std::string g_model;

void states(const gazebo_msgs::ModelStates& states) {
  for (size_t i = 0; i < states.name.size(); ++i) {
    if (states.name[i] != g_model) continue;
    const geometry_msgs::Point& p = states.pose[i].position;
    std::printf("position %.6f %.6f %.6f\n", p.x, p.y, p.z);
    std::fflush(stdout);
    ros::shutdown();
  }
}
}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "model_pose");
  if (argc != 2) {
    std::fprintf(stderr, "usage: model_pose MODEL\n");
    return 2;
  }
  g_model = argv[1];
  ros::NodeHandle nh;
  ros::Subscriber subscriber = nh.subscribe("/gazebo/model_states", 1, states);
  ros::spin();
  return 0;
}
