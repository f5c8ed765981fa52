// controller_manager's rules without ROS: load and its refusals, unload, the switch (STRICT and
// BEST_EFFORT, resource conflicts, the order of stopping and starting), update, reset and
// unload-all, on the book's robot (joint1 under an effort transmission).
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "onedof_sim/world.h"
#include "controller_set.h"
#include "controllers.h"
#include "robot_hw_sim.h"
#include "control_test_support.h"

namespace onedof_sim::control {
namespace {

using namespace testing_support;

constexpr const char* kNs = "/one_DOF_robot";
constexpr const char* kRecording = "test/RecordingController";
constexpr const char* kPosition = "effort_controllers/JointPositionController";
constexpr const char* kStates = "joint_state_controller/JointStateController";

// A controller that writes down what is asked of it ("<name> starting", ...) and claims the
// joints its `claims` parameter names (comma-separated), so any conflict can be set up.
class RecordingController : public Controller {
 public:
  RecordingController(std::string name, std::vector<std::string> joints,
                      std::vector<std::string>* log)
      : name_(std::move(name)), joints_(std::move(joints)), log_(log) {}
  void starting(int64_t time_ns) override { record("starting", time_ns); }
  void update(int64_t time_ns, int64_t) override { record("update", time_ns); }
  void stopping(int64_t time_ns) override { record("stopping", time_ns); }
  ClaimedResources claims() const override {
    return {interfaceTypeName(JointInterface::Effort), joints_};
  }

 private:
  void record(const char* call, int64_t time_ns) {
    log_->push_back(name_ + " " + call + " " + std::to_string(time_ns));
  }
  std::string name_;
  std::vector<std::string> joints_;
  std::vector<std::string>* log_;
};

// The built-in types and the recording one, writing into *log.
std::vector<ControllerType> typesWithRecording(std::vector<std::string>* log) {
  std::vector<ControllerType> types = controllerTypes();
  types.push_back({kRecording, "controller_interface::ControllerBase",
                   [log](RobotHwSim&, const ParamSource& params, const std::string& ns,
                         std::string*) -> std::unique_ptr<Controller> {
                     std::string claims;
                     params.getString(ns + "/claims", &claims);
                     std::vector<std::string> joints;
                     std::stringstream list(claims);
                     for (std::string joint; std::getline(list, joint, ',');)
                       joints.push_back(joint);
                     return std::make_unique<RecordingController>(ns.substr(ns.rfind('/') + 1),
                                                                  joints, log);
                   }});
  return types;
}

std::string ns(const std::string& name) { return std::string(kNs) + "/" + name; }

class ControllerSetTest : public ::testing::Test {
 protected:
  ControllerSetTest() {
    std::string error;
    EXPECT_TRUE(readRobotControlSpec(controlledUrdf(), "one_DOF_robot", &spec_, &error));
    EXPECT_TRUE(world_.spawn("one_DOF_robot", controlledUrdf(), ModelFormat::Urdf, Pose()).ok());
    std::vector<std::string> warnings;
    robot_ = std::make_unique<RobotHwSim>(world_, "one_DOF_robot", spec_, &warnings);
    set_ = std::make_unique<ControllerSet>(*robot_, typesWithRecording(&log_));
  }

  // A recording controller `name` claiming `claims`, loaded.
  void loadRecording(const std::string& name, const std::string& claims = "") {
    params_.strings[ns(name) + "/type"] = kRecording;
    params_.strings[ns(name) + "/claims"] = claims;
    ASSERT_EQ(set_->load(name, params_, ns(name)).outcome, LoadOutcome::Loaded);
  }

  // The book's joint1_position_controller's configuration under `name`.
  void configurePosition(const std::string& name) {
    params_.strings[ns(name) + "/type"] = kPosition;
    params_.strings[ns(name) + "/joint"] = "joint1";
    params_.numbers[ns(name) + "/pid/p"] = 10;
    params_.numbers[ns(name) + "/pid/d"] = 10;
  }

  std::map<std::string, ControllerState> states() const {
    std::map<std::string, ControllerState> states;
    for (const ControllerInfo& info : set_->list()) states[info.name] = info.state;
    return states;
  }

  SwitchResult switchStrict(const std::vector<std::string>& start,
                            const std::vector<std::string>& stop, int64_t time_ns = 7) {
    return set_->switchControllers(start, stop, Strictness::Strict, time_ns);
  }
  SwitchResult switchBestEffort(const std::vector<std::string>& start,
                                const std::vector<std::string>& stop, int64_t time_ns = 7) {
    return set_->switchControllers(start, stop, Strictness::BestEffort, time_ns);
  }

  World world_;
  RobotControlSpec spec_;
  std::unique_ptr<RobotHwSim> robot_;
  std::vector<std::string> log_;
  std::unique_ptr<ControllerSet> set_;
  MapParams params_;
};

using State = ControllerState;

TEST_F(ControllerSetTest, LoadRefusalsInControllerManagersOrder) {
  // No type.
  LoadResult result = set_->load("c", params_, ns("c"));
  EXPECT_EQ(result.outcome, LoadOutcome::NoType);
  // An unknown type, named.
  params_.strings[ns("c") + "/type"] = "effort_controllers/NoSuchController";
  result = set_->load("c", params_, ns("c"));
  EXPECT_EQ(result.outcome, LoadOutcome::UnknownType);
  EXPECT_EQ(result.type, "effort_controllers/NoSuchController");
  // A known type refusing its configuration, with its reason.
  params_.strings[ns("c") + "/type"] = kPosition;
  result = set_->load("c", params_, ns("c"));
  EXPECT_EQ(result.outcome, LoadOutcome::InitFailed);
  EXPECT_NE(result.error.find("No joint given"), std::string::npos) << result.error;
  EXPECT_FALSE(result.controller);
  EXPECT_EQ(set_->size(), 0u);
  // Loaded, initialized; a second load of the name refused before its configuration is read.
  configurePosition("c");
  result = set_->load("c", params_, ns("c"));
  ASSERT_EQ(result.outcome, LoadOutcome::Loaded);
  EXPECT_EQ(result.type, kPosition);
  EXPECT_TRUE(result.controller);
  params_.strings.erase(ns("c") + "/joint");
  EXPECT_EQ(set_->load("c", params_, ns("c")).outcome, LoadOutcome::AlreadyLoaded);
  ASSERT_EQ(set_->list().size(), 1u);
  const ControllerInfo info = set_->list().front();
  EXPECT_EQ(info.name, "c");
  EXPECT_EQ(info.type, kPosition);
  EXPECT_EQ(info.state, State::Initialized);
  EXPECT_EQ(info.claims.resources, std::vector<std::string>{"joint1"});
  EXPECT_STREQ(controllerStateName(info.state), "initialized");
}

TEST_F(ControllerSetTest, CommitRefusesANameLoadedSincePrepare) {
  configurePosition("c");
  LoadResult first = set_->prepareLoad("c", params_, ns("c"));
  LoadResult second = set_->prepareLoad("c", params_, ns("c"));
  ASSERT_EQ(first.outcome, LoadOutcome::Loaded);
  ASSERT_EQ(second.outcome, LoadOutcome::Loaded);
  EXPECT_EQ(set_->size(), 0u);  // prepared, not in the set
  EXPECT_EQ(set_->commitLoad("c", std::move(first)), LoadOutcome::Loaded);
  EXPECT_EQ(set_->commitLoad("c", std::move(second)), LoadOutcome::AlreadyLoaded);
  EXPECT_EQ(set_->size(), 1u);
}

TEST_F(ControllerSetTest, UnloadRefusesARunningController) {
  loadRecording("a");
  EXPECT_EQ(set_->unload("nope"), UnloadOutcome::NotLoaded);
  ASSERT_TRUE(switchStrict({"a"}, {}).ok());
  EXPECT_EQ(set_->unload("a"), UnloadOutcome::StillRunning);
  EXPECT_EQ(states(), (std::map<std::string, State>{{"a", State::Running}}));
  ASSERT_TRUE(switchStrict({}, {"a"}).ok());
  std::shared_ptr<Controller> unloaded;
  EXPECT_EQ(set_->unload("a", &unloaded), UnloadOutcome::Unloaded);
  EXPECT_TRUE(unloaded);  // handed back to the caller
  EXPECT_EQ(set_->size(), 0u);
  EXPECT_EQ(set_->unload("a"), UnloadOutcome::NotLoaded);
}

TEST_F(ControllerSetTest, StrictRefusesAnUnknownNameAndChangesNothing) {
  loadRecording("a");
  loadRecording("b");
  ASSERT_TRUE(switchStrict({"b"}, {}).ok());
  log_.clear();
  SwitchResult result = switchStrict({"a", "nope"}, {"b"});
  EXPECT_EQ(result.outcome, SwitchOutcome::UnknownToStart);
  EXPECT_EQ(result.controller, "nope");
  result = switchStrict({"a"}, {"b", "nope"});
  EXPECT_EQ(result.outcome, SwitchOutcome::UnknownToStop);
  EXPECT_EQ(result.controller, "nope");
  // The stop list is resolved first.
  EXPECT_EQ(switchStrict({"nope1"}, {"nope2"}).controller, "nope2");
  EXPECT_TRUE(log_.empty());
  EXPECT_EQ(states(), (std::map<std::string, State>{{"a", State::Initialized},
                                                     {"b", State::Running}}));
}

TEST_F(ControllerSetTest, BestEffortSkipsAnUnknownNameAndSwitchesTheRest) {
  loadRecording("a");
  loadRecording("b");
  ASSERT_TRUE(switchStrict({"b"}, {}).ok());
  log_.clear();
  EXPECT_TRUE(switchBestEffort({"a", "nope"}, {"nope", "b"}).ok());
  EXPECT_EQ(log_, (std::vector<std::string>{"b stopping 7", "a starting 7"}));
  EXPECT_EQ(states(), (std::map<std::string, State>{{"a", State::Running},
                                                     {"b", State::Stopped}}));
}

TEST_F(ControllerSetTest, StrictRefusesWhatIsAlreadyInTheWantedState) {
  loadRecording("a");
  loadRecording("b");
  ASSERT_TRUE(switchStrict({"a"}, {}).ok());
  log_.clear();
  SwitchResult result = switchStrict({"a"}, {});
  EXPECT_EQ(result.outcome, SwitchOutcome::AlreadyRunning);
  EXPECT_EQ(result.controller, "a");
  result = switchStrict({}, {"b"});
  EXPECT_EQ(result.outcome, SwitchOutcome::NotRunning);
  EXPECT_EQ(result.controller, "b");
  // Refused as a whole: b is not started beside the refused stop of a stopped one.
  ASSERT_TRUE(switchStrict({}, {"a"}).ok());
  log_.clear();
  EXPECT_EQ(switchStrict({"b"}, {"a"}).outcome, SwitchOutcome::NotRunning);
  EXPECT_TRUE(log_.empty());
  EXPECT_EQ(states(), (std::map<std::string, State>{{"a", State::Stopped},
                                                     {"b", State::Initialized}}));
}

TEST_F(ControllerSetTest, BestEffortDropsWhatIsAlreadyInTheWantedState) {
  loadRecording("a");
  loadRecording("b");
  ASSERT_TRUE(switchStrict({"a"}, {}).ok());
  log_.clear();
  // a runs: not restarted; b is not running: not stopped, but started.
  EXPECT_TRUE(switchBestEffort({"a", "b"}, {"b"}).ok());
  EXPECT_EQ(log_, (std::vector<std::string>{"b starting 7"}));
  EXPECT_EQ(states(), (std::map<std::string, State>{{"a", State::Running},
                                                     {"b", State::Running}}));
}

TEST_F(ControllerSetTest, StopsInTheOrderAskedThenStartsInTheOrderAsked) {
  for (const char* name : {"a", "b", "c", "d", "e"}) loadRecording(name);
  ASSERT_TRUE(switchStrict({"a", "c"}, {}, 1).ok());
  log_.clear();
  // Starts listed before stops, both against load order; a name asked twice acts once.
  ASSERT_TRUE(switchStrict({"e", "b", "e"}, {"c", "a"}, 2).ok());
  EXPECT_EQ(log_, (std::vector<std::string>{"c stopping 2", "a stopping 2", "e starting 2",
                                            "b starting 2"}));
  log_.clear();
  // Stopped and started in one switch: a restart, stopping first.
  ASSERT_TRUE(switchStrict({"d", "b"}, {"b"}, 3).ok());
  EXPECT_EQ(log_, (std::vector<std::string>{"b stopping 3", "d starting 3", "b starting 3"}));
  EXPECT_EQ(states(), (std::map<std::string, State>{{"a", State::Stopped},
                                                     {"b", State::Running},
                                                     {"c", State::Stopped},
                                                     {"d", State::Running},
                                                     {"e", State::Running}}));
}

TEST_F(ControllerSetTest, TwoControllersMayNotRunOnOneJoint) {
  configurePosition("first");
  configurePosition("second");
  params_.strings[ns("states") + "/type"] = kStates;
  params_.numbers[ns("states") + "/publish_rate"] = 50;
  for (const char* name : {"first", "second", "states"})
    ASSERT_EQ(set_->load(name, params_, ns(name)).outcome, LoadOutcome::Loaded);
  // Both at once: refused, in either strictness, and neither runs.
  for (Strictness strictness : {Strictness::Strict, Strictness::BestEffort}) {
    SwitchResult result = set_->switchControllers({"first", "second"}, {}, strictness, 0);
    EXPECT_EQ(result.outcome, SwitchOutcome::ResourceConflict);
    EXPECT_EQ(result.resource, "joint1");
  }
  EXPECT_EQ(states().at("first"), State::Initialized);
  EXPECT_EQ(states().at("second"), State::Initialized);
  // One runs; the other may not join it, but may take over in one switch.
  ASSERT_TRUE(switchStrict({"first", "states"}, {}).ok());  // the state controller claims none
  EXPECT_EQ(switchBestEffort({"second"}, {}).outcome, SwitchOutcome::ResourceConflict);
  EXPECT_EQ(states().at("first"), State::Running);
  EXPECT_TRUE(switchStrict({"second"}, {"first"}).ok());
  EXPECT_EQ(states(), (std::map<std::string, State>{{"first", State::Stopped},
                                                     {"second", State::Running},
                                                     {"states", State::Running}}));
}

TEST_F(ControllerSetTest, ConflictAmongRecordingControllersChangesNothing) {
  loadRecording("a", "joint1");
  loadRecording("b", "joint2,joint1");
  loadRecording("c", "joint2");
  ASSERT_TRUE(switchStrict({"a", "c"}, {}).ok());
  log_.clear();
  // b would share joint1 with a: the stop of c in the same switch does not happen either.
  EXPECT_EQ(switchBestEffort({"b"}, {"c"}).outcome, SwitchOutcome::ResourceConflict);
  EXPECT_TRUE(log_.empty());
  EXPECT_TRUE(switchBestEffort({"b"}, {"a", "c"}).ok());
  EXPECT_EQ(log_, (std::vector<std::string>{"a stopping 7", "c stopping 7", "b starting 7"}));
}

TEST_F(ControllerSetTest, UpdateRunsTheRunningInLoadOrderResetRestartsThem) {
  loadRecording("a");
  loadRecording("b");
  loadRecording("c");
  EXPECT_EQ(set_->lastUpdateNs(), 0);
  ASSERT_TRUE(switchStrict({"c", "a"}, {}).ok());
  log_.clear();
  set_->update(10, 1, false);
  EXPECT_EQ(log_, (std::vector<std::string>{"a update 10", "c update 10"}));
  EXPECT_EQ(set_->lastUpdateNs(), 10);
  log_.clear();
  set_->update(20, 10, true);
  EXPECT_EQ(log_, (std::vector<std::string>{"a stopping 20", "a starting 20", "a update 20",
                                            "c stopping 20", "c starting 20", "c update 20"}));
}

TEST_F(ControllerSetTest, UnloadAllStopsTheRunningAndHandsEveryOneBack) {
  loadRecording("a");
  loadRecording("b");
  ASSERT_TRUE(switchStrict({"b"}, {}).ok());
  log_.clear();
  const std::vector<std::shared_ptr<Controller>> unloaded = set_->unloadAll(30);
  EXPECT_EQ(unloaded.size(), 2u);
  EXPECT_EQ(log_, (std::vector<std::string>{"b stopping 30"}));
  EXPECT_EQ(set_->size(), 0u);
}

}  // namespace
}  // namespace onedof_sim::control
