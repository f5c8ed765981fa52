// The ROS face of onedof_sim: Gazebo's ROS API (gazebo_ros services and topics) over a World.
//
// One object owns the node handles, the world and the fixed-step loop (turtlesim style). Service
// callbacks run on an AsyncSpinner; they and the step loop share one mutex around the world, held
// only for world calls, never while doing ROS I/O (stage_ros). Requests that change how the world
// advances (pause, step, a controller's command in lock-step) only set state under that mutex and
// wake the loop; the loop alone steps.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>

#include <dynamic_reconfigure/Config.h>
#include <dynamic_reconfigure/Reconfigure.h>

#include <gazebo_msgs/ApplyBodyWrench.h>
#include <gazebo_msgs/ApplyJointEffort.h>
#include <gazebo_msgs/BodyRequest.h>
#include <gazebo_msgs/DeleteLight.h>
#include <gazebo_msgs/DeleteModel.h>
#include <gazebo_msgs/GetJointProperties.h>
#include <gazebo_msgs/GetLightProperties.h>
#include <gazebo_msgs/GetLinkProperties.h>
#include <gazebo_msgs/GetLinkState.h>
#include <gazebo_msgs/GetModelProperties.h>
#include <gazebo_msgs/GetModelState.h>
#include <gazebo_msgs/GetPhysicsProperties.h>
#include <gazebo_msgs/GetWorldProperties.h>
#include <gazebo_msgs/JointRequest.h>
#include <gazebo_msgs/LinkState.h>
#include <gazebo_msgs/ModelState.h>
#include <gazebo_msgs/SetJointProperties.h>
#include <gazebo_msgs/SetLightProperties.h>
#include <gazebo_msgs/SetLinkProperties.h>
#include <gazebo_msgs/SetLinkState.h>
#include <gazebo_msgs/SetModelConfiguration.h>
#include <gazebo_msgs/SetModelState.h>
#include <gazebo_msgs/SetPhysicsProperties.h>
#include <gazebo_msgs/SpawnModel.h>
#include <onedof_sim/StepSimulation.h>
#include <onedof_sim/world.h>

#include "control/gazebo_ros_control.h"
#include "lockstep.h"

namespace onedof_sim {

// The parameter that puts ROS nodes on simulated time (/clock).
constexpr const char* kUseSimTime = "/use_sim_time";

// Start-up settings of the node (see readNodeOptions for the parameter names).
struct NodeOptions {
  std::string engine = World::engineNames().front();
  PhysicsParams physics;
  double max_update_rate = 1000.0;       // steps per wall second; 0 = as fast as possible
  bool paused = false;
  double states_publish_frequency = 0;   // Hz of sim time for model/link_states; 0 = every step
  std::vector<std::string> model_path;   // where SDF's model:// URIs resolve (World::setModelPath)
  Lockstep::Options lockstep;
};

// Reads the private start-up parameters and gzserver's command-line flags (args without the
// program name and ROS remappings). Returns false and sets *error on an invalid value.
bool readNodeOptions(const ros::NodeHandle& private_nh, const std::vector<std::string>& args,
                     NodeOptions* options, std::string* error);

class GazeboApi {
 public:
  explicit GazeboApi(const NodeOptions& options);
  ~GazeboApi();

  // Steps the world at the configured pace until ROS shuts down (SIGINT).
  void run();

 private:
  // Locks the world for a service callback. Counts waiting callbacks so that the step loop, which
  // re-locks right after unlocking when running as fast as possible, lets them in first.
  class WorldLock {
   public:
    explicit WorldLock(GazeboApi& api);
    std::unique_lock<std::mutex>& held() { return lock_; }
   private:
    std::unique_lock<std::mutex> lock_;
  };

  struct StepOutput;
  void stepOnce(StepOutput* out);
  bool awaitControllers(std::unique_lock<std::mutex>& lock, StepOutput* out);
  void showWakeUpClock(const std::vector<Lockstep::Awaited>& awaited);
  void publish(const StepOutput& out);
  void publishClock(int64_t time_ns);
  // The latest time not published for want of subscribers (-1: none), for the latched /clock
  // once the loop stops.
  void publishHeldClock();
  void refreshClockFrequency();
  void pace(double max_update_rate, bool resumed);

  // Services (all under /gazebo/).
  // With the caller's name: lock-step tells a controller at work from one asleep, and says whom
  // it waits for.
  bool getJointProperties(
      ros::ServiceEvent<gazebo_msgs::GetJointProperties::Request, gazebo_msgs::GetJointProperties::Response>& event);
  bool applyJointEffort(
      ros::ServiceEvent<gazebo_msgs::ApplyJointEffort::Request, gazebo_msgs::ApplyJointEffort::Response>& event);
  bool setJointProperties(gazebo_msgs::SetJointProperties::Request& req,
                          gazebo_msgs::SetJointProperties::Response& res);
  bool clearJointForces(gazebo_msgs::JointRequest::Request& req, gazebo_msgs::JointRequest::Response& res);
  bool applyBodyWrench(gazebo_msgs::ApplyBodyWrench::Request& req, gazebo_msgs::ApplyBodyWrench::Response& res);
  bool clearBodyWrenches(gazebo_msgs::BodyRequest::Request& req, gazebo_msgs::BodyRequest::Response& res);
  bool spawnUrdfModel(gazebo_msgs::SpawnModel::Request& req, gazebo_msgs::SpawnModel::Response& res);
  bool spawnSdfModel(gazebo_msgs::SpawnModel::Request& req, gazebo_msgs::SpawnModel::Response& res);
  bool spawnModel(ModelFormat requested, gazebo_msgs::SpawnModel::Request& req, gazebo_msgs::SpawnModel::Response& res);
  // gazebo_ros_control for a spawned URDF that carries its plugin tag.
  void startRobotControl(const std::string& model, const std::string& urdf);
  control::LockWorld lockWorld();
  bool deleteModel(gazebo_msgs::DeleteModel::Request& req, gazebo_msgs::DeleteModel::Response& res);
  bool getModelState(gazebo_msgs::GetModelState::Request& req, gazebo_msgs::GetModelState::Response& res);
  bool setModelState(gazebo_msgs::SetModelState::Request& req, gazebo_msgs::SetModelState::Response& res);
  bool getLinkState(gazebo_msgs::GetLinkState::Request& req, gazebo_msgs::GetLinkState::Response& res);
  bool setLinkState(gazebo_msgs::SetLinkState::Request& req, gazebo_msgs::SetLinkState::Response& res);
  bool setModelConfiguration(gazebo_msgs::SetModelConfiguration::Request& req,
                             gazebo_msgs::SetModelConfiguration::Response& res);
  bool getModelProperties(gazebo_msgs::GetModelProperties::Request& req, gazebo_msgs::GetModelProperties::Response& res);
  bool getWorldProperties(gazebo_msgs::GetWorldProperties::Request& req, gazebo_msgs::GetWorldProperties::Response& res);
  bool getLinkProperties(gazebo_msgs::GetLinkProperties::Request& req, gazebo_msgs::GetLinkProperties::Response& res);
  bool setLinkProperties(gazebo_msgs::SetLinkProperties::Request& req,
                         gazebo_msgs::SetLinkProperties::Response& res);
  bool getLightProperties(gazebo_msgs::GetLightProperties::Request& req,
                          gazebo_msgs::GetLightProperties::Response& res);
  bool setLightProperties(gazebo_msgs::SetLightProperties::Request& req,
                          gazebo_msgs::SetLightProperties::Response& res);
  bool deleteLight(gazebo_msgs::DeleteLight::Request& req, gazebo_msgs::DeleteLight::Response& res);
  bool getPhysicsProperties(gazebo_msgs::GetPhysicsProperties::Request& req,
                            gazebo_msgs::GetPhysicsProperties::Response& res);
  bool setPhysicsProperties(gazebo_msgs::SetPhysicsProperties::Request& req,
                            gazebo_msgs::SetPhysicsProperties::Response& res);
  // Both physics setters; the text is the refusal, or the confirmation. Publishes the new
  // parameter_updates on success.
  Status applyPhysics(const PhysicsParams& params, double max_update_rate, std::string* text);
  // dynamic_reconfigure as gazebo_ros serves it (set_parameters, parameter_descriptions,
  // parameter_updates), with gazebo_ros' PhysicsConfig.
  bool setParameters(dynamic_reconfigure::Reconfigure::Request& req,
                     dynamic_reconfigure::Reconfigure::Response& res);
  dynamic_reconfigure::Config physicsConfig();
  bool pausePhysics(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  // /gazebo/step_simulation: served on its own thread (step_spinner_), as it holds its caller
  // until the loop has done the steps, while the other services go on being served.
  bool stepSimulation(StepSimulation::Request& req, StepSimulation::Response& res);
  bool unpausePhysics(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  bool resetSimulation(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  bool resetWorld(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);

  // Topics /gazebo/set_model_state and /gazebo/set_link_state: the services without a reply.
  void setModelStateTopic(const gazebo_msgs::ModelState::ConstPtr& msg);
  void setLinkStateTopic(const gazebo_msgs::LinkState::ConstPtr& msg);
  Status applyModelState(const gazebo_msgs::ModelState& state);
  Status applyLinkState(const gazebo_msgs::LinkState& state);

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;

  // Guarded by mutex_.
  std::mutex mutex_;
  std::condition_variable wake_loop_;  // unpaused, steps requested, a controller's command
  std::condition_variable steps_done_;
  World world_;
  bool paused_;
  double max_update_rate_;
  Lockstep lockstep_;
  Lockstep::Clock::time_point last_command_at_;  // the latest accepted apply_joint_effort
  bool between_stops_ = false;  // a lock-stepped controller's period runs (requests wait)
  std::condition_variable at_stop_;
  int64_t clock_ahead_ns_ = -1;  // the wake-up clock shown ahead of the world, until it gets there
  struct StepRequest {
    bool active = false;  // until the steps are done (and, in lock-step, the controllers acted)
    uint64_t remaining = 0;
  } step_request_;
  std::atomic<int> waiting_callbacks_{0};
  // Per model that carries gazebo_ros_control: its controllers, run before every step.
  std::map<std::string, std::unique_ptr<control::GazeboRosControl>> robot_controls_;

  // Step-loop state (only the loop thread touches these).
  double states_publish_frequency_;
  double clock_frequency_ = 0;  // /gazebo/pub_clock_frequency; <= 0: every step
  std::chrono::steady_clock::time_point next_param_refresh_;
  std::chrono::steady_clock::time_point deadline_;
  int64_t last_clock_ns_ = -1;
  int64_t held_clock_ns_ = -1;
  int64_t last_states_ns_ = -1;
  int64_t last_markers_ns_ = -1;

  ros::Publisher clock_pub_;
  ros::Publisher model_states_pub_;
  ros::Publisher link_states_pub_;
  ros::Publisher markers_pub_;
  ros::Publisher parameter_descriptions_pub_;  // latched
  ros::Publisher parameter_updates_pub_;       // latched
  std::vector<ros::ServiceServer> services_;
  std::vector<ros::Subscriber> subscribers_;
  ros::AsyncSpinner spinner_;
  ros::CallbackQueue step_queue_;
  ros::ServiceServer step_service_;
  ros::AsyncSpinner step_spinner_;
};

}  // namespace onedof_sim
