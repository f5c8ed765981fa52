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
  // The node is the clock, so it must not run on its own /clock: roscpp subscribes every node to
  // /clock when /use_sim_time is set at start-up, and then delivers each step's clock back to
  // this process, waking a thread per step (3 to 5 times the cost of the step itself, measured).
  // roscpp 1.15 has no init option against it (NoSimTime came later), but it reads the parameter
  // through name remapping, so remapping that one name for this node keeps it on wall time.
  // The node sets the real /use_sim_time for the others (GazeboApi).
  std::vector<char*> args_with_own_time(argv, argv + argc);
  std::string own_time_remap = std::string(onedof_sim::kUseSimTime) + ":=" +
                               onedof_sim::kUseSimTime + "_is_for_the_clock_subscribers";
  args_with_own_time.push_back(&own_time_remap[0]);
  int ros_argc = static_cast<int>(args_with_own_time.size());
  ros::init(ros_argc, args_with_own_time.data(), "gazebo");  // removes the ROS remappings from it
  // Alive until the end: when the last NodeHandle goes, roscpp shuts down (console output too).
  ros::NodeHandle private_nh("~");
  const std::vector<std::string> args(args_with_own_time.begin() + 1,
                                      args_with_own_time.begin() + ros_argc);

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
