// controller_manager's own side (Noetic's ControllerManager without its services): the controllers
// loaded for one robot and their states, with load, unload, switch, update and list under
// controller_manager's rules. Free of ROS: every call answers with an outcome and the facts that
// explain it, and the ROS face (src/ros/control/controller_manager.h) words them as
// controller_manager's log messages. Not thread-safe: the owner serializes every call (the node
// holds the world's lock around them).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "controllers.h"
#include "param_source.h"
#include "robot_hw_sim.h"

namespace onedof_sim::control {

// ros_control's states as this set uses them: loaded, started, stopped after running.
enum class ControllerState { Initialized, Running, Stopped };

// "initialized", "running" or "stopped", as list_controllers reports the state.
const char* controllerStateName(ControllerState state);

// controller_manager_msgs/SwitchController's strictness, with its values.
enum class Strictness { BestEffort = 1, Strict = 2 };

struct ControllerInfo {
  std::string name;
  std::string type;
  ControllerState state = ControllerState::Initialized;
  ClaimedResources claims;
};

enum class LoadOutcome {
  Loaded,
  NoType,         // <ns>/type is not set (or not a string)
  UnknownType,    // no controller type of that name
  AlreadyLoaded,  // a controller of that name is in the set
  InitFailed,     // the type refused its configuration
};

// A load in progress: the controller built from its parameters, not yet in the set.
struct LoadResult {
  LoadOutcome outcome = LoadOutcome::NoType;
  std::string type;   // as <ns>/type names it
  std::string error;  // InitFailed: the type's reason
  std::shared_ptr<Controller> controller;  // set when outcome is Loaded
};

enum class UnloadOutcome { Unloaded, NotLoaded, StillRunning };

enum class SwitchOutcome {
  Switched,
  UnknownToStop,     // STRICT: a name to stop is not loaded
  UnknownToStart,    // STRICT: a name to start is not loaded
  NotRunning,        // STRICT: a controller to stop is not running
  AlreadyRunning,    // STRICT: a controller to start runs and is not stopped in the same switch
  ResourceConflict,  // two controllers that would run claim one joint
};

struct SwitchResult {
  SwitchOutcome outcome = SwitchOutcome::Switched;
  std::string controller;  // the controller refused (every outcome but Switched and a conflict)
  std::string resource;    // ResourceConflict: the joint claimed twice
  bool ok() const { return outcome == SwitchOutcome::Switched; }
};

class ControllerSet {
 public:
  // Controllers are built on robot's joints, of the given types; the set is used only while
  // robot lives.
  explicit ControllerSet(RobotHwSim& robot,
                         std::vector<ControllerType> types = controllerTypes())
      : robot_(robot), types_(std::move(types)) {}

  // The types it loads (list_controller_types).
  const std::vector<ControllerType>& types() const { return types_; }

  // Loading in two parts, so that the owner can connect a built controller's outputs before it
  // joins the set: prepareLoad builds it from the parameters under ns (the controller's
  // namespace: `type` and what that type reads), commitLoad adds it, initialized. Refusals in
  // controller_manager's order: no type, unknown type, already loaded, refused configuration.
  LoadResult prepareLoad(const std::string& name, const ParamSource& params,
                         const std::string& ns) const;
  // Loaded, or AlreadyLoaded when a controller of that name joined since prepareLoad.
  LoadOutcome commitLoad(const std::string& name, LoadResult prepared);
  // Both parts at once.
  LoadResult load(const std::string& name, const ParamSource& params, const std::string& ns);

  // A running controller stays: it has to be stopped first. *unloaded (if given) takes the
  // controller, for the owner to destroy where it likes.
  UnloadOutcome unload(const std::string& name, std::shared_ptr<Controller>* unloaded = nullptr);

  // controller_manager's switch, done at once: names are resolved (stop list first), then every
  // loaded controller is checked in load order (STRICT refuses a stop of one not running and a
  // start of one running that is not also stopped; BEST_EFFORT drops those requests and unknown
  // names), then the joints claimed by the controllers that would run are checked for a
  // conflict. Only if all holds: the ones to stop are stopped, in the order asked, then the ones
  // to start are started, in the order asked (one both stopped and started restarts). A name
  // asked twice acts once. time_ns is what stopping()/starting() are told.
  SwitchResult switchControllers(const std::vector<std::string>& start,
                                 const std::vector<std::string>& stop, Strictness strictness,
                                 int64_t time_ns);

  // The control loop: every running controller updated, in load order. reset_controllers
  // restarts them first (stopping(), starting()), as gazebo_ros_control's reset asks.
  void update(int64_t time_ns, int64_t period_ns, bool reset_controllers);
  // The time of the last update (0 before the first): the services' time.
  int64_t lastUpdateNs() const { return last_update_ns_; }

  // In load order.
  std::vector<ControllerInfo> list() const;
  size_t size() const { return loaded_.size(); }

  // Stops the running controllers and unloads every one. Returns them, in load order, for the
  // owner to destroy where it likes.
  std::vector<std::shared_ptr<Controller>> unloadAll(int64_t time_ns);

 private:
  struct Loaded {
    std::string name;
    std::string type;
    ControllerState state = ControllerState::Initialized;
    std::shared_ptr<Controller> controller;
  };

  Loaded* find(const std::string& name);
  const Loaded* find(const std::string& name) const;

  RobotHwSim& robot_;
  std::vector<ControllerType> types_;
  std::vector<Loaded> loaded_;
  int64_t last_update_ns_ = 0;
};

}  // namespace onedof_sim::control
