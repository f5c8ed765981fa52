#include "controller_manager.h"

#include <sstream>
#include <utility>

#include <control_msgs/JointControllerState.h>
#include <sensor_msgs/JointState.h>
#include <std_msgs/Float64.h>

namespace onedof_sim::control {

namespace {

using controller_manager_msgs::SwitchController;

// A controller's namespace on the parameter server, read once (unlocked: it asks the master),
// then looked up as roscpp reads parameters (an int is a double too).
class RosParams : public ParamSource {
 public:
  explicit RosParams(const std::string& ns) : ns_(ns) {
    if (!ros::param::get(ns, tree_)) tree_ = XmlRpc::XmlRpcValue();
  }
  bool has(const std::string& key) const override { return find(key) != nullptr; }
  bool getDouble(const std::string& key, double* value) const override {
    const XmlRpc::XmlRpcValue* found = find(key);
    if (!found) return false;
    auto& v = const_cast<XmlRpc::XmlRpcValue&>(*found);  // XmlRpcValue reads through non-const
    if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) *value = double(v);
    else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) *value = int(v);
    else return false;
    return true;
  }
  bool getBool(const std::string& key, bool* value) const override {
    const XmlRpc::XmlRpcValue* found = find(key);
    if (!found || found->getType() != XmlRpc::XmlRpcValue::TypeBoolean) return false;
    *value = bool(const_cast<XmlRpc::XmlRpcValue&>(*found));
    return true;
  }
  bool getString(const std::string& key, std::string* value) const override {
    const XmlRpc::XmlRpcValue* found = find(key);
    if (!found || found->getType() != XmlRpc::XmlRpcValue::TypeString) return false;
    *value = std::string(const_cast<XmlRpc::XmlRpcValue&>(*found));
    return true;
  }

 private:
  // key: the namespace, then "/"-separated members.
  const XmlRpc::XmlRpcValue* find(const std::string& key) const {
    if (key.compare(0, ns_.size() + 1, ns_ + "/") != 0) return nullptr;
    const XmlRpc::XmlRpcValue* node = &tree_;
    std::istringstream path(key.substr(ns_.size() + 1));
    for (std::string member; std::getline(path, member, '/');) {
      if (node->getType() != XmlRpc::XmlRpcValue::TypeStruct || !node->hasMember(member))
        return nullptr;
      node = &const_cast<XmlRpc::XmlRpcValue&>(*node)[member];
    }
    return node;
  }

  std::string ns_;
  XmlRpc::XmlRpcValue tree_;
};

// joint_states and state topics: queue sizes as ros_controllers' realtime publishers have them.
constexpr uint32_t kJointStatesQueue = 4;
constexpr uint32_t kStateQueue = 1;

// controller_manager's words for a switch the set refused.
std::string switchRefusal(const SwitchResult& result) {
  switch (result.outcome) {
    case SwitchOutcome::UnknownToStop:
    case SwitchOutcome::UnknownToStart:
      return std::string("Could not ") +
             (result.outcome == SwitchOutcome::UnknownToStop ? "stop" : "start") +
             " controller with name '" + result.controller +
             "' because no controller with this name exists";
    case SwitchOutcome::NotRunning:
      return "Could not stop controller '" + result.controller + "' since it is not running";
    case SwitchOutcome::AlreadyRunning:
      return "Controller '" + result.controller + "' is already running";
    case SwitchOutcome::ResourceConflict:
      return "Could not switch controllers, due to resource conflict (joint '" + result.resource +
             "' would be commanded by two running controllers)";
    case SwitchOutcome::Switched: break;
  }
  return "";
}

}  // namespace

ControllerManager::ControllerManager(const std::string& robot_namespace, RobotHwSim& robot,
                                     LockWorld lock_world)
    : robot_namespace_(robot_namespace),
      lock_world_(std::move(lock_world)),
      nh_(robot_namespace),
      controllers_(robot) {
  ros::NodeHandle n(nh_, "controller_manager");
  services_ = {
      n.advertiseService("load_controller", &ControllerManager::loadController, this),
      n.advertiseService("unload_controller", &ControllerManager::unloadController, this),
      n.advertiseService("switch_controller", &ControllerManager::switchController, this),
      n.advertiseService("list_controllers", &ControllerManager::listControllers, this),
      n.advertiseService("list_controller_types", &ControllerManager::listControllerTypes, this),
      n.advertiseService("reload_controller_libraries",
                         &ControllerManager::reloadControllerLibraries, this),
  };
}

ControllerManager::~ControllerManager() {
  for (auto& service : services_) service.shutdown();
}

void ControllerManager::update(int64_t time_ns, int64_t period_ns, bool reset_controllers) {
  controllers_.update(time_ns, period_ns, reset_controllers);
}

std::vector<Publication> ControllerManager::takePublications() {
  return std::exchange(publications_, {});
}

std::vector<std::shared_ptr<void>> ControllerManager::unloadAll(int64_t time_ns) {
  std::vector<std::shared_ptr<void>> leftovers;
  for (std::shared_ptr<Controller>& controller : controllers_.unloadAll(time_ns))
    leftovers.push_back(std::move(controller));  // with their publishers
  for (auto& [name, subscriber] : command_subscribers_)
    leftovers.push_back(std::make_shared<ros::Subscriber>(std::move(subscriber)));
  command_subscribers_.clear();
  return leftovers;
}

void ControllerManager::connectOutputs(const std::string& name, Controller& controller) {
  ros::NodeHandle controller_nh(nh_, name);
  ros::Publisher state_pub =
      controller_nh.advertise<control_msgs::JointControllerState>("state", kStateQueue);
  ros::Publisher joint_states_pub =
      nh_.advertise<sensor_msgs::JointState>("joint_states", kJointStatesQueue);
  // Called in the step loop, world locked: the message is built now, sent after unlocking.
  controller.publish_state = [this, state_pub](const JointControllerStateFacts& facts) {
    auto msg = boost::make_shared<control_msgs::JointControllerState>();
    msg->header.stamp.fromNSec(uint64_t(facts.stamp_ns));
    msg->set_point = facts.set_point;
    msg->process_value = facts.process_value;
    msg->process_value_dot = facts.process_value_dot;
    msg->error = facts.error;
    msg->time_step = facts.time_step;
    msg->command = facts.command;
    msg->p = facts.gains.p;
    msg->i = facts.gains.i;
    msg->d = facts.gains.d;
    msg->i_clamp = facts.gains.i_max;
    msg->antiwindup = facts.gains.antiwindup;
    publications_.push_back([state_pub, msg] { state_pub.publish(msg); });
  };
  controller.publish_joint_states = [this, joint_states_pub](const JointStatesFacts& facts) {
    auto msg = boost::make_shared<sensor_msgs::JointState>();
    msg->header.stamp.fromNSec(uint64_t(facts.stamp_ns));
    msg->name = facts.names;
    msg->position = facts.position;
    msg->velocity = facts.velocity;
    msg->effort = facts.effort;
    publications_.push_back([joint_states_pub, msg] { joint_states_pub.publish(msg); });
  };
}

bool ControllerManager::loadController(controller_manager_msgs::LoadController::Request& req,
                                       controller_manager_msgs::LoadController::Response& res) {
  res.ok = false;
  const std::string ns = ros::names::resolve(robot_namespace_ + "/" + req.name);
  const RosParams params(ns);
  LoadResult prepared;
  {
    std::unique_lock<std::mutex> lock = lock_world_();
    prepared = controllers_.prepareLoad(req.name, params, ns);
  }
  switch (prepared.outcome) {
    case LoadOutcome::NoType:
      ROS_ERROR("Could not load controller '%s' because the type was not specified. Did you load "
                "the controller configuration on the parameter server (namespace: '%s')?",
                req.name.c_str(), ns.c_str());
      return true;
    case LoadOutcome::UnknownType:
      ROS_ERROR("Could not load controller '%s' because controller type '%s' does not exist.",
                req.name.c_str(), prepared.type.c_str());
      ROS_ERROR("Use 'rosservice call %s/controller_manager/list_controller_types' to get the "
                "available types", robot_namespace_.c_str());
      return true;
    case LoadOutcome::AlreadyLoaded:
      ROS_ERROR("A controller named '%s' was already loaded inside the controller manager",
                req.name.c_str());
      return true;
    case LoadOutcome::InitFailed:
      ROS_ERROR("Initializing controller '%s' failed: %s", req.name.c_str(),
                prepared.error.c_str());
      return true;
    case LoadOutcome::Loaded: break;
  }
  // Topics are set up and, on a refusal, taken down unlocked (they talk to the master); the
  // controller runs only once started.
  const std::string type = prepared.type;
  const std::shared_ptr<Controller> controller = prepared.controller;
  connectOutputs(req.name, *controller);
  ros::Subscriber command_subscriber;
  if (controller->takesCommand()) {
    std::shared_ptr<Controller> target = controller;
    command_subscriber = ros::NodeHandle(nh_, req.name).subscribe<std_msgs::Float64>(
        "command", 1, [target](const std_msgs::Float64::ConstPtr& msg) {
          target->setCommand(msg->data);
        });
  }
  {
    std::unique_lock<std::mutex> lock = lock_world_();
    if (controllers_.commitLoad(req.name, std::move(prepared)) != LoadOutcome::Loaded) {
      // Loaded meanwhile by a concurrent call.
      ROS_ERROR("A controller named '%s' was already loaded inside the controller manager",
                req.name.c_str());
      return true;
    }
    command_subscribers_[req.name] = std::move(command_subscriber);
  }
  ROS_INFO("%s: loaded controller '%s' (%s)", robot_namespace_.c_str(), req.name.c_str(),
           type.c_str());
  res.ok = true;
  return true;
}

bool ControllerManager::unloadController(controller_manager_msgs::UnloadController::Request& req,
                                         controller_manager_msgs::UnloadController::Response& res) {
  res.ok = false;
  // Destroyed unlocked: the subscriber waits for a callback in flight, the publishers talk to the
  // master.
  std::shared_ptr<Controller> controller;
  ros::Subscriber command_subscriber;
  {
    std::unique_lock<std::mutex> lock = lock_world_();
    switch (controllers_.unload(req.name, &controller)) {
      case UnloadOutcome::NotLoaded:
        ROS_ERROR("Could not unload controller with name '%s' because no controller with this "
                  "name exists", req.name.c_str());
        return true;
      case UnloadOutcome::StillRunning:
        ROS_ERROR("Could not unload controller with name '%s' because it is still running",
                  req.name.c_str());
        return true;
      case UnloadOutcome::Unloaded: break;
    }
    auto found = command_subscribers_.find(req.name);
    command_subscriber = std::move(found->second);
    command_subscribers_.erase(found);
  }
  command_subscriber.shutdown();
  res.ok = true;
  return true;
}

// The switch is done at once, under the world's lock: the stopped controllers command nothing
// from the next step on and the started ones act at it, so start_asap and timeout have nothing
// to wait for.
bool ControllerManager::switchController(controller_manager_msgs::SwitchController::Request& req,
                                         controller_manager_msgs::SwitchController::Response& res) {
  if (req.strictness == 0) {
    ROS_WARN("Controller Manager: To switch controllers you need to specify a strictness level of "
             "controller_manager_msgs::SwitchController::STRICT (%d) or ::BEST_EFFORT (%d). "
             "Defaulting to ::BEST_EFFORT.",
             SwitchController::Request::STRICT, SwitchController::Request::BEST_EFFORT);
  }
  const Strictness strictness = req.strictness == SwitchController::Request::STRICT
                                    ? Strictness::Strict
                                    : Strictness::BestEffort;
  SwitchResult result;
  {
    std::unique_lock<std::mutex> lock = lock_world_();
    result = controllers_.switchControllers(req.start_controllers, req.stop_controllers,
                                            strictness, controllers_.lastUpdateNs());
  }
  res.ok = result.ok();
  if (!res.ok) ROS_ERROR_STREAM(switchRefusal(result));
  return true;
}

bool ControllerManager::listControllers(controller_manager_msgs::ListControllers::Request&,
                                        controller_manager_msgs::ListControllers::Response& res) {
  std::vector<ControllerInfo> infos;
  {
    std::unique_lock<std::mutex> lock = lock_world_();
    infos = controllers_.list();
  }
  for (const ControllerInfo& info : infos) {
    controller_manager_msgs::ControllerState state;
    state.name = info.name;
    state.type = info.type;
    state.state = controllerStateName(info.state);
    controller_manager_msgs::HardwareInterfaceResources resources;
    resources.hardware_interface = info.claims.hardware_interface;
    resources.resources = info.claims.resources;
    state.claimed_resources.push_back(resources);
    res.controller.push_back(state);
  }
  return true;
}

bool ControllerManager::listControllerTypes(
    controller_manager_msgs::ListControllerTypes::Request&,
    controller_manager_msgs::ListControllerTypes::Response& res) {
  // Unlocked: the set's types are fixed at its construction.
  for (const ControllerType& type : controllers_.types()) {
    res.types.push_back(type.name);
    res.base_classes.push_back(type.base_class);
  }
  return true;
}

// The controller types are built in, so there is nothing to reload: as controller_manager, it
// refuses while controllers are loaded unless force_kill, which stops and unloads them all.
bool ControllerManager::reloadControllerLibraries(
    controller_manager_msgs::ReloadControllerLibraries::Request& req,
    controller_manager_msgs::ReloadControllerLibraries::Response& res) {
  std::vector<std::shared_ptr<void>> leftovers;
  {
    std::unique_lock<std::mutex> lock = lock_world_();
    const size_t loaded = controllers_.size();
    if (loaded > 0 && !req.force_kill) {
      ROS_ERROR("Controller manager: Cannot reload controller libraries because there are still "
                "%i controllers running", int(loaded));
      res.ok = false;
      return true;
    }
    if (loaded > 0) ROS_INFO("Controller manager: Killing all running controllers");
    leftovers = unloadAll(controllers_.lastUpdateNs());
  }
  leftovers.clear();  // unlocked: subscribers wait for callbacks in flight
  res.ok = true;
  return true;
}

}  // namespace onedof_sim::control
