// The ROS face of onedof_sim: Gazebo's ROS API (gazebo_ros_api_plugin's services and topics under
// /gazebo/) over the loop that owns the world (SimLoop), and the model plugins spawned models name.
//
// Handlers only: each converts its request (conversions.h), asks the loop (a function run under
// the world lock, a step request, a command), and words the answer (status_text.h). They run on
// two threads serving the global queue; /gazebo/step_simulation (served with
// ~enable_step_simulation) on a spinner of its own, as it holds its caller until the steps are
// done while the other services go on being served; apply_joint_effort on a thread
// of its own, which tells the loop when each reply is out (lock-step needs to know).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
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
#include <onedof_sim/ResetModel.h>
#include <onedof_sim/StepSimulation.h>
#include <onedof_sim/world.h>

#include "node_options.h"
#include "physics_config.h"
#include "plugins/model_plugin.h"
#include "sim_loop.h"

namespace onedof_sim {

// A model of the world file the simulator refuses (what says why): the node ends at start-up.
class WorldModelRefused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class GazeboApi {
 public:
  // plugin_types: the model plugins a spawned model may name (plugins::modelPluginRegistry(),
  // and any a caller adds); its sensors' plugins are plugins::sensorPluginRegistry()'s. The
  // models of options.world are spawned first, before any service is up; throws
  // WorldModelRefused for one the world refuses.
  GazeboApi(const NodeOptions& options, std::vector<plugins::ModelPluginType> plugin_types);
  ~GazeboApi();

  // Steps the world at the configured pace until ROS shuts down (SIGINT).
  void run() { loop_.run(); }

 private:
  template <class Request, class Response>
  using Event = ros::ServiceEvent<Request, Response>;

  // Joints. With the caller's name: lock-step tells a controller at work from one asleep, and
  // says whom it waits for.
  bool getJointProperties(
      Event<gazebo_msgs::GetJointProperties::Request, gazebo_msgs::GetJointProperties::Response>& event);
  bool applyJointEffort(
      Event<gazebo_msgs::ApplyJointEffort::Request, gazebo_msgs::ApplyJointEffort::Response>& event);
  bool setJointProperties(gazebo_msgs::SetJointProperties::Request& req,
                          gazebo_msgs::SetJointProperties::Response& res);
  bool clearJointForces(gazebo_msgs::JointRequest::Request& req, gazebo_msgs::JointRequest::Response& res);

  // Links.
  bool applyBodyWrench(gazebo_msgs::ApplyBodyWrench::Request& req, gazebo_msgs::ApplyBodyWrench::Response& res);
  bool clearBodyWrenches(gazebo_msgs::BodyRequest::Request& req, gazebo_msgs::BodyRequest::Response& res);
  bool getLinkState(gazebo_msgs::GetLinkState::Request& req, gazebo_msgs::GetLinkState::Response& res);
  bool setLinkState(gazebo_msgs::SetLinkState::Request& req, gazebo_msgs::SetLinkState::Response& res);
  bool getLinkProperties(gazebo_msgs::GetLinkProperties::Request& req, gazebo_msgs::GetLinkProperties::Response& res);
  bool setLinkProperties(gazebo_msgs::SetLinkProperties::Request& req,
                         gazebo_msgs::SetLinkProperties::Response& res);

  // Models.
  bool spawnUrdfModel(gazebo_msgs::SpawnModel::Request& req, gazebo_msgs::SpawnModel::Response& res);
  bool spawnSdfModel(gazebo_msgs::SpawnModel::Request& req, gazebo_msgs::SpawnModel::Response& res);
  bool spawnModel(ModelFormat requested, gazebo_msgs::SpawnModel::Request& req, gazebo_msgs::SpawnModel::Response& res);
  // What both spawn services and the world file do with a model: check, prepare unlocked,
  // spawn, create its plugins (robot_namespace for those that name none); `via` names the way it
  // came in the log line. A body of implausible inertia is logged, and its warning appended to
  // *warnings (optional) for the reply.
  Status spawn(const std::string& name, const std::string& xml, ModelFormat format,
               const Pose& pose, const std::string& reference_frame,
               const std::string& robot_namespace, const std::string& via,
               std::string* warnings = nullptr);
  // The same, the model made by `prepare` (given the world's model path) where the one above
  // reads xml; xml is what its plugins are read from.
  using Prepare = std::function<PreparedModel(const std::vector<std::string>& model_path)>;
  Status spawn(const std::string& name, const Prepare& prepare, const std::string& xml,
               ModelFormat format, const Pose& pose, const std::string& reference_frame,
               const std::string& robot_namespace, const std::string& via,
               std::string* warnings = nullptr);
  void spawnWorldModels(const WorldFile& world);
  bool deleteModel(gazebo_msgs::DeleteModel::Request& req, gazebo_msgs::DeleteModel::Response& res);
  bool getModelState(gazebo_msgs::GetModelState::Request& req, gazebo_msgs::GetModelState::Response& res);
  bool setModelState(gazebo_msgs::SetModelState::Request& req, gazebo_msgs::SetModelState::Response& res);
  bool setModelConfiguration(gazebo_msgs::SetModelConfiguration::Request& req,
                             gazebo_msgs::SetModelConfiguration::Response& res);
  bool getModelProperties(gazebo_msgs::GetModelProperties::Request& req, gazebo_msgs::GetModelProperties::Response& res);
  bool getWorldProperties(gazebo_msgs::GetWorldProperties::Request& req, gazebo_msgs::GetWorldProperties::Response& res);

  // Lights: there is no renderer, so the world has none.
  bool getLightProperties(gazebo_msgs::GetLightProperties::Request& req,
                          gazebo_msgs::GetLightProperties::Response& res);
  bool setLightProperties(gazebo_msgs::SetLightProperties::Request& req,
                          gazebo_msgs::SetLightProperties::Response& res);
  bool deleteLight(gazebo_msgs::DeleteLight::Request& req, gazebo_msgs::DeleteLight::Response& res);

  // Physics, and how the world advances.
  bool getPhysicsProperties(gazebo_msgs::GetPhysicsProperties::Request& req,
                            gazebo_msgs::GetPhysicsProperties::Response& res);
  bool setPhysicsProperties(gazebo_msgs::SetPhysicsProperties::Request& req,
                            gazebo_msgs::SetPhysicsProperties::Response& res);
  // Both physics setters; the text is the refusal, or the confirmation. Publishes the new
  // parameter_updates on success.
  Status applyPhysics(const PhysicsSettings& settings, std::string* text);
  bool setParameters(dynamic_reconfigure::Reconfigure::Request& req,
                     dynamic_reconfigure::Reconfigure::Response& res);
  bool pausePhysics(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  bool unpausePhysics(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  bool stepSimulation(StepSimulation::Request& req, StepSimulation::Response& res);
  bool resetSimulation(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  bool resetWorld(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  bool resetModel(ResetModel::Request& req, ResetModel::Response& res);

  // Topics /gazebo/set_model_state and /gazebo/set_link_state: the services without a reply.
  void setModelStateTopic(const gazebo_msgs::ModelState::ConstPtr& msg);
  void setLinkStateTopic(const gazebo_msgs::LinkState::ConstPtr& msg);
  Status applyModelState(const gazebo_msgs::ModelState& state);
  Status applyLinkState(const gazebo_msgs::LinkState& state);
  void serveGlobalQueue();
  // The services under /gazebo/ and the topics of the API (the dynamic reconfigure topics, the
  // set_*_state subscriptions), and step_simulation when asked for; left out with
  // ~enable_ros_network false.
  void advertiseServices(bool step_simulation);

  SimLoop loop_;
  std::vector<plugins::ModelPluginType> plugin_types_;
  bool loading_world_ = false;  // spawnWorldModels: spawns leave the heap untrimmed
  ros::NodeHandle private_nh_;
  ros::Publisher parameter_descriptions_pub_;  // latched
  ros::Publisher parameter_updates_pub_;       // latched
  std::vector<ros::ServiceServer> services_;
  std::vector<ros::Subscriber> subscribers_;
  std::atomic<bool> stopping_{false};
  std::vector<std::thread> service_threads_;  // serveGlobalQueue
  ros::CallbackQueue step_queue_;
  ros::ServiceServer step_service_;
  ros::ServiceServer reset_model_service_;  // while the world view's markers are advertised
  ros::AsyncSpinner step_spinner_;
  ros::CallbackQueue effort_queue_;
  ros::ServiceServer effort_service_;
  std::thread effort_thread_;
};

}  // namespace onedof_sim
