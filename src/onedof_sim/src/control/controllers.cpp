#include "controllers.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

namespace onedof_sim::control {

namespace {

constexpr double kNsToS = 1e-9;
constexpr const char* kControllerBase = "controller_interface::ControllerBase";
// ros_controllers' JointPositionController and JointVelocityController publish their state on
// every tenth update (loop_count_ % 10 == 0), the first one included.
constexpr uint64_t kStateEveryUpdates = 10;

// --- angles (the angles package), as ros_controllers computes a position error ----------------

double normalizeAnglePositive(double angle) {
  return std::fmod(std::fmod(angle, 2 * M_PI) + 2 * M_PI, 2 * M_PI);
}

double normalizeAngle(double angle) {
  const double a = normalizeAnglePositive(angle);
  return a > M_PI ? a - 2 * M_PI : a;
}

double shortestAngularDistance(double from, double to) { return normalizeAngle(to - from); }

double twoPiComplement(double angle) {
  if (angle > 2 * M_PI || angle < -2 * M_PI) angle = std::fmod(angle, 2 * M_PI);
  if (angle < 0) return 2 * M_PI + angle;
  if (angle > 0) return -2 * M_PI + angle;
  return 2 * M_PI;
}

// The shorter way round that stays within [left, right]; the shortest when neither does.
double shortestAngularDistanceWithLargeLimits(double from, double to, double left, double right) {
  double delta = shortestAngularDistance(from, to);
  double delta_2pi = twoPiComplement(delta);
  if (std::abs(delta) > std::abs(delta_2pi)) std::swap(delta, delta_2pi);
  if (left > right) return delta;
  if (left <= from + delta && from + delta <= right) return delta;
  if (left <= from + delta_2pi && from + delta_2pi <= right) return delta_2pi;
  return delta;
}

// --- configuration ------------------------------------------------------------------------------

// The joint that `<ns>/joint` names, through its EffortJointInterface.
std::optional<EffortJointHandle> readEffortJoint(RobotHwSim& robot, const ParamSource& params,
                                                 const std::string& ns, std::string* error) {
  std::string name;
  if (!params.getString(ns + "/joint", &name)) {
    *error = params.has(ns + "/joint") ? "parameter '" + ns + "/joint' is not a string"
                                       : "No joint given (namespace: " + ns + ")";
    return std::nullopt;
  }
  std::optional<EffortJointHandle> joint = robot.effortJoint(name);
  if (!joint)
    *error = "Could not find resource '" + name + "' in '" +
             interfaceTypeName(JointInterface::Effort) +
             "' (the joint must be in a <transmission> with that hardwareInterface)";
  return joint;
}

ClaimedResources claimOf(const JointStateHandle& joint) {
  return {interfaceTypeName(JointInterface::Effort), {joint.name()}};
}

// --- the controllers ----------------------------------------------------------------------------

class JointStateController : public Controller {
 public:
  JointStateController(std::vector<JointStateHandle> joints, double publish_rate)
      : joints_(std::move(joints)), publish_rate_(publish_rate) {}

  void starting(int64_t time_ns) override { last_publish_ns_ = time_ns; }

  // As joint_state_controller: due once the period has passed (strictly), the next one due a
  // whole period later, so the rate holds whatever the step.
  void update(int64_t time_ns, int64_t) override {
    const int64_t period_ns = std::llround(1e9 / publish_rate_);
    if (!(publish_rate_ > 0) || !(last_publish_ns_ + period_ns < time_ns)) return;
    last_publish_ns_ += period_ns;
    if (!publish_joint_states) return;
    JointStatesFacts facts;
    facts.stamp_ns = time_ns;
    for (const JointStateHandle& joint : joints_) {
      facts.names.push_back(joint.name());
      facts.position.push_back(joint.position());
      facts.velocity.push_back(joint.velocity());
      facts.effort.push_back(joint.effort());
    }
    publish_joint_states(facts);
  }

  ClaimedResources claims() const override {
    return {"hardware_interface::JointStateInterface", {}};
  }

 private:
  std::vector<JointStateHandle> joints_;
  double publish_rate_;
  int64_t last_publish_ns_ = 0;
};

// What the effort-commanding PID controllers share: a joint, a Pid, the state they publish.
class PidJointController : public Controller {
 public:
  PidJointController(EffortJointHandle joint, const PidGains& gains)
      : joint_(joint), pid_(gains) {}
  bool takesCommand() const override { return true; }
  ClaimedResources claims() const override { return claimOf(joint_); }

 protected:
  void publishState(int64_t time_ns, int64_t period_ns, double set_point, double process_value,
                    double error, double command) {
    if (loop_count_++ % kStateEveryUpdates != 0 || !publish_state) return;
    JointControllerStateFacts facts;
    facts.stamp_ns = time_ns;
    facts.set_point = set_point;
    facts.process_value = process_value;
    facts.process_value_dot = joint_.velocity();
    facts.error = error;
    facts.time_step = period_ns * kNsToS;
    facts.command = command;
    facts.gains = pid_.gains();
    publish_state(facts);
  }

  EffortJointHandle joint_;
  Pid pid_;
  uint64_t loop_count_ = 0;
};

class EffortJointPositionController : public PidJointController {
 public:
  using PidJointController::PidJointController;

  void starting(int64_t) override {
    command_.store(limited(joint_.position()));
    pid_.reset();
  }

  void update(int64_t time_ns, int64_t period_ns) override {
    const double command = limited(command_.load());
    const double error = positionError(joint_, command);
    const double effort = pid_.computeCommand(error, period_ns * kNsToS);
    joint_.setCommand(effort);
    publishState(time_ns, period_ns, command, joint_.position(), error, effort);
  }

 private:
  // Revolute and prismatic joints: the command held within the joint's limits.
  double limited(double command) const {
    if (joint_.type() == JointType::Continuous || !joint_.hasLimits()) return command;
    return std::clamp(command, joint_.lower(), joint_.upper());
  }
};

class EffortJointVelocityController : public PidJointController {
 public:
  using PidJointController::PidJointController;

  void starting(int64_t) override {
    command_.store(0.0);
    pid_.reset();
  }

  void update(int64_t time_ns, int64_t period_ns) override {
    const double command = command_.load();
    const double error = command - joint_.velocity();
    const double effort = pid_.computeCommand(error, period_ns * kNsToS);
    joint_.setCommand(effort);
    publishState(time_ns, period_ns, command, joint_.velocity(), error, effort);
  }
};

// forward_command_controller: the command is the effort.
class JointEffortController : public Controller {
 public:
  explicit JointEffortController(EffortJointHandle joint) : joint_(joint) {}
  bool takesCommand() const override { return true; }
  void starting(int64_t) override { command_.store(0.0); }
  void update(int64_t, int64_t) override { joint_.setCommand(command_.load()); }
  ClaimedResources claims() const override { return claimOf(joint_); }

 private:
  EffortJointHandle joint_;
};

// --- the registry -------------------------------------------------------------------------------

template <typename PidController>
std::unique_ptr<Controller> makePidController(RobotHwSim& robot, const ParamSource& params,
                                              const std::string& ns, std::string* error) {
  std::optional<EffortJointHandle> joint = readEffortJoint(robot, params, ns, error);
  PidGains gains;
  if (!joint || !readPidGains(params, ns + "/pid", &gains, error)) return nullptr;
  return std::make_unique<PidController>(*joint, gains);
}

}  // namespace

double positionError(const JointStateHandle& joint, double command) {
  switch (joint.type()) {
    case JointType::Continuous: return shortestAngularDistance(joint.position(), command);
    case JointType::Revolute:
      if (joint.hasLimits())
        return shortestAngularDistanceWithLargeLimits(joint.position(), command, joint.lower(),
                                                      joint.upper());
      return shortestAngularDistance(joint.position(), command);
    default: return command - joint.position();
  }
}

const std::vector<ControllerType>& controllerTypes() {
  static const std::vector<ControllerType> types = {
      {"joint_state_controller/JointStateController", kControllerBase,
       [](RobotHwSim& robot, const ParamSource& params, const std::string& ns,
          std::string* error) -> std::unique_ptr<Controller> {
         double rate = 0;
         if (!params.getDouble(ns + "/publish_rate", &rate)) {
           *error = "Parameter 'publish_rate' not set (namespace: " + ns + ")";
           return nullptr;
         }
         if (!std::isfinite(rate) || rate <= 0) {
           *error = "Parameter '" + ns + "/publish_rate' must be a positive number of Hz";
           return nullptr;
         }
         return std::make_unique<JointStateController>(robot.jointStates(), rate);
       }},
      {"effort_controllers/JointPositionController", kControllerBase,
       makePidController<EffortJointPositionController>},
      {"effort_controllers/JointVelocityController", kControllerBase,
       makePidController<EffortJointVelocityController>},
      {"effort_controllers/JointEffortController", kControllerBase,
       [](RobotHwSim& robot, const ParamSource& params, const std::string& ns,
          std::string* error) -> std::unique_ptr<Controller> {
         std::optional<EffortJointHandle> joint = readEffortJoint(robot, params, ns, error);
         if (!joint) return nullptr;
         return std::make_unique<JointEffortController>(*joint);
       }},
      // Listed, as a client may ask for it, and refused with the reason: the engines move
      // joints by effort only, so nothing here can hold a joint at a commanded position.
      {"position_controllers/JointPositionController", kControllerBase,
       [](RobotHwSim&, const ParamSource&, const std::string& ns,
          std::string* error) -> std::unique_ptr<Controller> {
         *error = "position_controllers/JointPositionController (namespace: " + ns +
                  ") needs a joint the simulator sets to a position, and this simulator moves "
                  "joints by effort only: use effort_controllers/JointPositionController with "
                  "pid gains and an EffortJointInterface transmission";
         return nullptr;
       }},
  };
  return types;
}

const ControllerType* findControllerType(const std::string& name,
                                         const std::vector<ControllerType>& types) {
  for (const ControllerType& type : types)
    if (type.name == name) return &type;
  return nullptr;
}

}  // namespace onedof_sim::control
