// controller_manager (Noetic) for one robot namespace, inside the simulator: the ROS face of a
// ControllerSet (control/controller_set.h). Its six services under
// <robotNamespace>/controller_manager/, with controller_manager_msgs' types and
// controller_manager's log messages; the controllers' parameters from the parameter server;
// their `command` topics and what they publish.
//
// Threading as GazeboApi's: service callbacks and command subscribers run on the node's spinner;
// the services change the controllers under the world's lock (lock_world), the step loop updates
// them under it (update) and publishes, after unlocking, what they handed out (takePublications).
// Command callbacks only store the value (Controller::setCommand): they never wait for the world.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <controller_manager_msgs/ListControllerTypes.h>
#include <controller_manager_msgs/ListControllers.h>
#include <controller_manager_msgs/LoadController.h>
#include <controller_manager_msgs/ReloadControllerLibraries.h>
#include <controller_manager_msgs/SwitchController.h>
#include <controller_manager_msgs/UnloadController.h>
#include <ros/ros.h>

#include "controller_set.h"
#include "controllers.h"
#include "plugins/model_plugin.h"
#include "robot_hw_sim.h"

namespace onedof_sim::control {

using plugins::LockWorld;
using plugins::Publication;

class ControllerManager {
 public:
  // Serves under robot_namespace ("/one_DOF_robot"); controllers act on robot's joints.
  ControllerManager(const std::string& robot_namespace, RobotHwSim& robot, LockWorld lock_world);
  ~ControllerManager();

  // The step loop, world locked: every loaded controller in load order, the running ones
  // updated. reset_controllers restarts the running ones first (gazebo_ros_control's Reset).
  void update(int64_t time_ns, int64_t period_ns, bool reset_controllers);
  std::vector<Publication> takePublications();

  // Stops and unloads every controller, world locked; what must be destroyed unlocked (their
  // subscribers) is returned.
  std::vector<std::shared_ptr<void>> unloadAll(int64_t time_ns);

 private:
  bool loadController(controller_manager_msgs::LoadController::Request& req,
                      controller_manager_msgs::LoadController::Response& res);
  bool unloadController(controller_manager_msgs::UnloadController::Request& req,
                        controller_manager_msgs::UnloadController::Response& res);
  bool switchController(controller_manager_msgs::SwitchController::Request& req,
                        controller_manager_msgs::SwitchController::Response& res);
  bool listControllers(controller_manager_msgs::ListControllers::Request& req,
                       controller_manager_msgs::ListControllers::Response& res);
  bool listControllerTypes(controller_manager_msgs::ListControllerTypes::Request& req,
                           controller_manager_msgs::ListControllerTypes::Response& res);
  bool reloadControllerLibraries(controller_manager_msgs::ReloadControllerLibraries::Request& req,
                                 controller_manager_msgs::ReloadControllerLibraries::Response& res);

  // The publishers a controller of this name hands its facts to.
  void connectOutputs(const std::string& name, Controller& controller);

  std::string robot_namespace_;
  LockWorld lock_world_;
  ros::NodeHandle nh_;  // the robot namespace

  // Guarded by the world's lock.
  ControllerSet controllers_;
  std::map<std::string, ros::Subscriber> command_subscribers_;  // by controller name
  std::vector<Publication> publications_;

  // Last: shut down first, waiting for callbacks in flight.
  std::vector<ros::ServiceServer> services_;
};

}  // namespace onedof_sim::control
