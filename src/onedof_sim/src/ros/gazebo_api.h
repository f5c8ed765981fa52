// The ROS face of onedof_sim: Gazebo's ROS API (gazebo_ros services and topics) over a World.
//
// One object owns the node handles, the world and the fixed-step loop (turtlesim style). Service
// callbacks run on an AsyncSpinner; they and the step loop share one mutex around the world, held
// only for world calls, never while doing ROS I/O (stage_ros).
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <std_srvs/Empty.h>

#include <onedof_sim/ApplyBodyWrench.h>
#include <onedof_sim/ApplyJointEffort.h>
#include <onedof_sim/BodyRequest.h>
#include <onedof_sim/DeleteModel.h>
#include <onedof_sim/GetJointProperties.h>
#include <onedof_sim/GetLinkProperties.h>
#include <onedof_sim/GetLinkState.h>
#include <onedof_sim/GetModelProperties.h>
#include <onedof_sim/GetModelState.h>
#include <onedof_sim/GetPhysicsProperties.h>
#include <onedof_sim/GetWorldProperties.h>
#include <onedof_sim/JointRequest.h>
#include <onedof_sim/LinkState.h>
#include <onedof_sim/ModelState.h>
#include <onedof_sim/SetLinkState.h>
#include <onedof_sim/SetModelConfiguration.h>
#include <onedof_sim/SetModelState.h>
#include <onedof_sim/SetPhysicsProperties.h>
#include <onedof_sim/SpawnModel.h>
#include <onedof_sim/world.h>

namespace onedof_sim {

// Start-up settings of the node (see readNodeOptions for the parameter names).
struct NodeOptions {
  std::string engine = World::engineNames().front();
  PhysicsParams physics;
  double max_update_rate = 1000.0;       // steps per wall second; 0 = as fast as possible
  bool paused = false;
  double states_publish_frequency = 0;   // Hz of sim time for model/link_states; 0 = every step
  std::vector<std::string> model_path;   // where SDF's model:// URIs resolve (World::setModelPath)
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
   private:
    std::unique_lock<std::mutex> lock_;
  };

  struct StepOutput;
  void stepOnce(StepOutput* out);
  void publish(const StepOutput& out);
  void refreshClockFrequency();
  void pace(double max_update_rate, bool resumed);

  // Services (all under /gazebo/).
  bool getJointProperties(GetJointProperties::Request& req, GetJointProperties::Response& res);
  bool applyJointEffort(ApplyJointEffort::Request& req, ApplyJointEffort::Response& res);
  bool clearJointForces(JointRequest::Request& req, JointRequest::Response& res);
  bool applyBodyWrench(ApplyBodyWrench::Request& req, ApplyBodyWrench::Response& res);
  bool clearBodyWrenches(BodyRequest::Request& req, BodyRequest::Response& res);
  bool spawnUrdfModel(SpawnModel::Request& req, SpawnModel::Response& res);
  bool spawnSdfModel(SpawnModel::Request& req, SpawnModel::Response& res);
  bool spawnModel(ModelFormat requested, SpawnModel::Request& req, SpawnModel::Response& res);
  bool deleteModel(DeleteModel::Request& req, DeleteModel::Response& res);
  bool getModelState(GetModelState::Request& req, GetModelState::Response& res);
  bool setModelState(SetModelState::Request& req, SetModelState::Response& res);
  bool getLinkState(GetLinkState::Request& req, GetLinkState::Response& res);
  bool setLinkState(SetLinkState::Request& req, SetLinkState::Response& res);
  bool setModelConfiguration(SetModelConfiguration::Request& req,
                             SetModelConfiguration::Response& res);
  bool getModelProperties(GetModelProperties::Request& req, GetModelProperties::Response& res);
  bool getWorldProperties(GetWorldProperties::Request& req, GetWorldProperties::Response& res);
  bool getLinkProperties(GetLinkProperties::Request& req, GetLinkProperties::Response& res);
  bool getPhysicsProperties(GetPhysicsProperties::Request& req,
                            GetPhysicsProperties::Response& res);
  bool setPhysicsProperties(SetPhysicsProperties::Request& req,
                            SetPhysicsProperties::Response& res);
  bool pausePhysics(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  bool unpausePhysics(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  bool resetSimulation(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  bool resetWorld(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);

  // Topics /gazebo/set_model_state and /gazebo/set_link_state: the services without a reply.
  void setModelStateTopic(const ModelState::ConstPtr& msg);
  void setLinkStateTopic(const LinkState::ConstPtr& msg);
  Status applyModelState(const ModelState& state);
  Status applyLinkState(const LinkState& state);

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;

  // Guarded by mutex_.
  std::mutex mutex_;
  std::condition_variable unpaused_;
  World world_;
  bool paused_;
  double max_update_rate_;
  std::atomic<int> waiting_callbacks_{0};

  // Step-loop state (only the loop thread touches these).
  double states_publish_frequency_;
  double clock_frequency_ = 0;  // /gazebo/pub_clock_frequency; <= 0: every step
  std::chrono::steady_clock::time_point next_param_refresh_;
  std::chrono::steady_clock::time_point deadline_;
  int64_t last_clock_ns_ = -1;
  int64_t last_states_ns_ = -1;
  int64_t last_markers_ns_ = -1;

  ros::Publisher clock_pub_;
  ros::Publisher model_states_pub_;
  ros::Publisher link_states_pub_;
  ros::Publisher markers_pub_;
  std::vector<ros::ServiceServer> services_;
  std::vector<ros::Subscriber> subscribers_;
  ros::AsyncSpinner spinner_;
};

}  // namespace onedof_sim
