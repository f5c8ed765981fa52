// rosrun onedof_sim onedof_sim: the simulator node, named `gazebo` as gzserver + gazebo_ros is.
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <ros/package.h>
#include <ros/ros.h>

#include "gazebo_api.h"

namespace {

// Where model://NAME resolves: this package's models/ first (as spawn_model -database searches),
// so the tutorial always gets the models the simulator was built for, then GAZEBO_MODEL_PATH.
std::vector<std::string> modelPath() {
  std::vector<std::string> folders{ros::package::getPath("onedof_sim") + "/models"};
  const char* env = std::getenv("GAZEBO_MODEL_PATH");
  std::istringstream entries(env ? env : "");
  for (std::string folder; std::getline(entries, folder, ':');) folders.push_back(folder);
  return folders;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && std::string(argv[1]) == "--list-physics") {
    // The engine registry, for the tools and tests that run one simulator per engine; before
    // ros::init, so that it needs no roscore.
    for (const std::string& name : onedof_sim::World::engineNames()) std::cout << name << "\n";
    return 0;
  }
  ros::init(argc, argv, "gazebo");  // removes the ROS remappings (_param:=value) from argv
  // Alive until the end: when the last NodeHandle goes, roscpp shuts down (console output too).
  ros::NodeHandle private_nh("~");
  const std::vector<std::string> args(argv + 1, argv + argc);

  onedof_sim::NodeOptions options;
  std::string error;
  if (!onedof_sim::readNodeOptions(private_nh, args, &options, &error)) {
    ROS_FATAL_STREAM("onedof_sim: " << error);
    return 1;
  }
  options.model_path = modelPath();
  try {
    onedof_sim::GazeboApi api(options);
    api.run();
  } catch (const std::invalid_argument& e) {
    // An unknown engine (World's constructor) or invalid physics parameters (setParams).
    ROS_FATAL_STREAM("onedof_sim: " << e.what());
    return 1;
  }
  return 0;
}
