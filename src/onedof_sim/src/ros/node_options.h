// The node's start-up settings: its private parameters and gzserver's command-line flags.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <ros/ros.h>

#include <onedof_sim/world.h>
#include <onedof_sim/world_file.h>

#include "lockstep.h"

namespace onedof_sim {

// The parameter that puts ROS nodes on simulated time (/clock).
constexpr const char* kUseSimTime = "/use_sim_time";
// The private parameters read while running (SimLoop): /clock's rate in Hz of sim time, and
// whether the node publishes the collision markers.
constexpr const char* kPubClockFrequency = "pub_clock_frequency";
constexpr const char* kEnableCollisionMarkers = "enable_collision_markers";
// The private parameter that serves the step service.
constexpr const char* kEnableStepSimulation = "enable_step_simulation";

// Start-up settings of the node (see readNodeOptions for the parameter names).
struct NodeOptions {
  std::string engine = World::engineNames().front();
  PhysicsParams physics;
  double max_update_rate = 1000.0;       // steps per wall second; 0 = as fast as possible
  bool paused = false;
  double states_publish_frequency = 0;   // Hz of sim time for model/link_states; 0 = every step
  std::vector<std::string> model_path;   // where SDF's model:// URIs resolve (World::setModelPath)
  Lockstep::Options lockstep;
  // Gazebo's ~enable_ros_network: false leaves the node's ROS API out (no /gazebo service nor
  // topic: model_states, link_states, the markers, the set_*_state subscriptions, the dynamic
  // reconfigure topics); /clock, the world, its plugins and the node's logger services remain.
  bool enable_ros_network = true;
  // The node's two names beyond gazebo_ros' (opt-in, so that by default the node advertises
  // exactly Gazebo's names): ~enable_step_simulation serves /gazebo/step_simulation (default:
  // ~lockstep's value, as a lock-stepped run is stepped with it); ~enable_collision_markers
  // publishes /gazebo/collision_markers (SimLoop also reads it while running: rviz's world view
  // sets it). Neither without the ROS network.
  bool enable_step_simulation = false;
  bool enable_collision_markers = false;
  // The world file named on the command line, read (world_loading.h); its models are spawned
  // before the services are up.
  std::optional<WorldFile> world;
};

// gzserver's command line as the node takes it: -u/--pause, -e ENGINE, and the world file (the
// last argument that is not a flag nor a flag's value). Every other argument is logged as
// ignored.
// The world gzserver starts with when given none: Gazebo's worlds/empty.world (this package's
// has it), its ground plane and sun.
constexpr const char* kDefaultWorldFile = "worlds/empty.world";

struct ServerArguments {
  bool paused = false;
  std::string engine;
  std::string world_file;  // empty: none given (kDefaultWorldFile is loaded)
};
ServerArguments parseServerArguments(const std::vector<std::string>& args);

// Reads the private start-up parameters and gzserver's flags (parseServerArguments of the
// arguments without the program name and ROS remappings) over options->world's settings. Returns
// false and sets *error on an invalid value.
bool readNodeOptions(const ros::NodeHandle& private_nh, const ServerArguments& arguments,
                     NodeOptions* options, std::string* error);

// The highest max_update_rate taken (steps per wall second): a step per microsecond, more than
// any world here steps; beyond it a rate paces nothing (0 asks for as fast as possible).
constexpr double kMaxPacedRate = 1e6;

// Empty if the node can pace at max_update_rate (steps per wall second), else why not.
std::string maxUpdateRateError(double rate);

// Sets /use_sim_time on the master unless it is set already: through the master, by its global
// name, as this node remaps /use_sim_time for itself (main.cpp).
void setUseSimTimeUnlessSet();

}  // namespace onedof_sim
