// An engine that fails inside a call must not take the process down. ODE is driven into a real
// internal error here (dxNormalize4's assertion inside dWorldStep, on a body given a non-finite
// angular velocity at the engine seam, past every check the world makes): the engine throws
// EngineFault instead of aborting, another ODE world in the same process steps on, and a World
// removes the model that failed, rebuilds its engine and steps on with every other model exactly
// where a world that never had that model would have it. A failure injected at the engine seam
// (FailingEngine) shows the world's order: the step retaken with the other solver, then only the
// model the step involves removed, else the world stopped.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "engine.h"
#include "../ground_plane.h"
#include "onedof_sim/world.h"
#include "world_impl.h"

namespace onedof_sim {

// An engine whose next plain step or ray query fails (EngineFault), around the world's own
// engine: the world's containment of a fault, on any engine. after_step: the step is taken first, so that
// the engine's contacts are the step's; retakes: whether it claims a second solver.
class FailingEngine : public core::Engine {
 public:
  FailingEngine(std::unique_ptr<core::Engine> engine, bool after_step, bool retakes)
      : engine_(std::move(engine)), after_step_(after_step), retakes_(retakes) {}
  void setParams(const PhysicsParams& params) override { engine_->setParams(params); }
  std::unique_ptr<core::EngineModel> addModel(const core::ModelSpec& spec) override {
    return engine_->addModel(spec);
  }
  bool exactSolver(const PhysicsParams& params) const override {
    return engine_->exactSolver(params);
  }
  void step(double dt, std::string* solver_message, bool retake) override {
    if (after_step_) engine_->step(dt, solver_message, retake);
    if (!retake) throw core::EngineFault("injected failure");
  }
  bool retakesFailedSteps(const PhysicsParams& params) const override {
    return retakes_ && engine_->retakesFailedSteps(params);
  }
  std::vector<core::BodyRef> contactBodies() const override { return engine_->contactBodies(); }
  void contacts(std::vector<core::EngineContact>* out) const override { engine_->contacts(out); }
  void castRays(const std::vector<Ray>&, std::vector<double>*) override {
    throw core::EngineFault("injected failure");
  }

 private:
  std::unique_ptr<core::Engine> engine_;
  bool after_step_, retakes_;
};

// The tests' way to the engine under a world (a friend of World).
struct WorldTestAccess {
  static core::EngineModel& engineModel(World& world, const std::string& model) {
    return *world.impl_->findModel(model)->engine_model;
  }
  // The world's next step or ray query fails inside its engine (FailingEngine); the world
  // replaces the engine as it contains the failure.
  static void failNextStep(World& world, bool after_step, bool retakes) {
    world.impl_->engine =
        std::make_unique<FailingEngine>(std::move(world.impl_->engine), after_step, retakes);
  }
};

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A 1 kg, 0.1 m box body with a contact-free life in the air.
core::ModelSpec boxSpec() {
  core::BodySpec body;
  body.mass = 1;
  body.ixx = body.iyy = body.izz = 1.0 / 600;
  core::ShapeSpec shape;
  shape.size = {0.1, 0.1, 0.1};
  body.shapes.push_back(shape);
  core::ModelSpec spec;
  spec.bodies.push_back(body);
  return spec;
}

std::unique_ptr<core::Engine> makeEngine(const std::string& name) {
  for (const core::EngineEntry& entry : core::engineRegistry())
    if (entry.name == name) {
      auto engine = entry.make();
      engine->setParams(PhysicsParams());
      return engine;
    }
  return nullptr;
}

// A body at (x, 0, 1) at rest, or spinning at a non-finite rate.
void place(core::EngineModel& model, double x, double spin) {
  Pose pose;
  pose.position = {x, 0, 1};
  Twist twist;
  twist.angular = {spin, 0, 0};
  model.setBodyState(0, pose, twist);
}

TEST(EngineFault, OdeAssertionInsideAStepThrowsAndAnotherWorldStepsOn) {
  auto failing = makeEngine("ode");
  ASSERT_TRUE(failing);
  auto failing_box = failing->addModel(boxSpec());
  failing_box->attachJoints({Pose()}, {});
  place(*failing_box, 0, kNaN);
  std::string message;
  try {
    failing->step(0.001, &message);
    FAIL() << "ODE stepped a body with a non-finite angular velocity without an error";
  } catch (const core::EngineFault& fault) {
    EXPECT_NE(std::string(fault.what()).find("assertion"), std::string::npos) << fault.what();
  }
  // A second call is refused, not run on ODE's inconsistent state.
  EXPECT_THROW(failing->step(0.001, &message), core::EngineFault);

  // Another ODE world in the same process falls as it should: the failed step's jobs stayed in
  // the failed world's own threading implementation.
  auto engine = makeEngine("ode");
  auto box = engine->addModel(boxSpec());
  box->attachJoints({Pose()}, {});
  place(*box, 0, 0);
  for (int i = 0; i < 100; ++i) engine->step(0.001, &message);
  const double z = box->bodyPose(0).position.z;
  EXPECT_NEAR(z, 1 - 0.5 * 9.8 * 0.1 * 0.1, 1e-3);
  // The failed engine and its model are destroyed without ODE's teardown asserting.
  failing_box.reset();
  failing.reset();
  for (int i = 0; i < 100; ++i) engine->step(0.001, &message);
  EXPECT_LT(box->bodyPose(0).position.z, z);
}

const char* kPendulum = R"(<robot name="pendulum">
  <link name="world"/>
  <link name="base"/>
  <joint name="fixed" type="fixed"><parent link="world"/><child link="base"/></joint>
  <link name="arm">
    <inertial><origin xyz="0 0 -0.5"/><mass value="1"/>
      <inertia ixx="0.084" ixy="0" ixz="0" iyy="0.084" iyz="0" izz="0.0013"/></inertial>
    <collision><origin xyz="0 0 -0.5"/><geometry><box size="0.05 0.05 1"/></geometry></collision>
  </link>
  <joint name="hinge" type="continuous"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 2"/><axis xyz="0 1 0"/></joint>
</robot>)";

const char* kBox = R"(<robot name="box"><link name="body">
  <inertial><mass value="1"/><inertia ixx="0.0017" ixy="0" ixz="0" iyy="0.0017" iyz="0" izz="0.0017"/></inertial>
  <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
</link></robot>)";

Pose at(double x, double z) {
  Pose pose;
  pose.position = {x, 0, z};
  return pose;
}

// On the ground plane, the pendulum swinging from 1 rad and a box dropped beside it; `victim`: a
// box far from both.
void populate(World* world, bool victim) {
  testing_support::addGroundPlane(*world);
  const Status spawned = world->spawn("pendulum", kPendulum, ModelFormat::Urdf, Pose());
  ASSERT_TRUE(spawned.ok()) << spawned;
  ASSERT_TRUE(world->setModelConfiguration("pendulum", {"hinge"}, {1.0}).ok());
  ASSERT_TRUE(world->spawn("box", kBox, ModelFormat::Urdf, at(1, 0.3)).ok());
  if (victim) ASSERT_TRUE(world->spawn("victim", kBox, ModelFormat::Urdf, at(10, 1)).ok());
  ASSERT_TRUE(world->applyJointEffort("hinge", 0.5, 0, 300000000).ok());
}

void expectSameState(World& world, World& twin) {
  JointInfo joint, twin_joint;
  ASSERT_TRUE(world.jointInfo("hinge", &joint).ok());
  ASSERT_TRUE(twin.jointInfo("hinge", &twin_joint).ok());
  EXPECT_NEAR(joint.position, twin_joint.position, 1e-9);
  EXPECT_NEAR(joint.rate, twin_joint.rate, 1e-9);
  Pose pose, twin_pose;
  Twist twist, twin_twist;
  ASSERT_TRUE(world.modelState("box", "", &pose, &twist).ok());
  ASSERT_TRUE(twin.modelState("box", "", &twin_pose, &twin_twist).ok());
  EXPECT_NEAR(pose.position.x, twin_pose.position.x, 1e-9);
  EXPECT_NEAR(pose.position.z, twin_pose.position.z, 1e-9);
  EXPECT_NEAR(pose.orientation.w, twin_pose.orientation.w, 1e-9);
}

TEST(EngineFault, OdeFailingInsideAStepRemovesTheModelAndTheWorldStepsOn) {
  World world("ode"), twin("ode");
  populate(&world, true);
  populate(&twin, false);
  for (int i = 0; i < 200; ++i) {
    ASSERT_TRUE(world.step().ok());
    ASSERT_TRUE(twin.step().ok());
  }
  world.takeWarnings();
  twin.takeWarnings();

  // Past the world's checks: only the engine seam takes a non-finite state.
  Pose pose;
  Twist twist;
  ASSERT_TRUE(world.modelState("victim", "", &pose, &twist).ok());
  twist.angular.x = kNaN;
  WorldTestAccess::engineModel(world, "victim").setBodyState(0, pose, twist);
  const Status failed = world.step();
  ASSERT_TRUE(twin.step().ok());
  EXPECT_EQ(failed.code, StatusCode::EngineFault) << failed;
  EXPECT_NE(failed.subject.find("assertion"), std::string::npos) << failed.subject;
  EXPECT_EQ(world.modelNames(), (std::vector<std::string>{"ground_plane", "pendulum", "box"}));
  const std::vector<std::string> warnings = world.takeWarnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("'victim'"), std::string::npos) << warnings[0];
  EXPECT_EQ(world.timeNs(), twin.timeNs());
  expectSameState(world, twin);

  // The world steps on, its effort job running out on time, and its models keep every property.
  for (int i = 0; i < 800; ++i) {
    ASSERT_TRUE(world.step().ok());
    ASSERT_TRUE(twin.step().ok());
  }
  EXPECT_EQ(world.takeWarnings(), twin.takeWarnings());
  expectSameState(world, twin);
  LinkInfo link;
  ASSERT_TRUE(world.linkProperties("pendulum::arm", &link).ok());
  EXPECT_EQ(link.mass, 1);

  // A second failure is contained as the first; a model spawned after it steps.
  ASSERT_TRUE(world.spawn("victim", kBox, ModelFormat::Urdf, at(10, 1)).ok());
  ASSERT_TRUE(world.modelState("box", "", &pose, &twist).ok());
  twist.linear.z = kNaN;
  WorldTestAccess::engineModel(world, "box").setBodyState(0, pose, twist);
  EXPECT_EQ(world.step().code, StatusCode::EngineFault);
  EXPECT_EQ(world.modelNames(), (std::vector<std::string>{"ground_plane", "pendulum", "victim"}));
  for (int i = 0; i < 500; ++i) ASSERT_TRUE(world.step().ok());
  ASSERT_TRUE(world.modelState("victim", "", &pose, &twist).ok());
  EXPECT_NEAR(pose.position.z, 0.05, 0.01);  // fell onto the ground
}

class EngineFaultOn : public ::testing::TestWithParam<std::string> {};

std::vector<std::string> settledNames(World* world) {
  for (int i = 0; i < 300; ++i) EXPECT_TRUE(world->step().ok());
  world->takeWarnings();
  return world->modelNames();
}

// A step that fails inside the engine is taken again from where it started with the engine's
// other solver (ODE's dWorldQuickStep), on a new engine, before any model is lost; an engine
// with one solver cannot: one that names the bodies of the step's contacts (dart) has the model
// they belong to taken out (the box on the ground), one with nothing to pin the failure on
// (bullet) stops the world unmoved.
TEST_P(EngineFaultOn, AFailedStepIsTakenAgainWithTheOtherSolverBeforeAnyModelIsLost) {
  World world(GetParam());
  populate(&world, true);
  const std::vector<std::string> names = settledNames(&world);
  const int64_t start_ns = world.timeNs();
  Pose before;
  Twist twist;
  ASSERT_TRUE(world.modelState("box", "", &before, &twist).ok());

  WorldTestAccess::failNextStep(world, false, true);
  const Status stepped = world.step();
  std::vector<std::string> kept = names;
  if (GetParam() == "dart") kept.erase(std::find(kept.begin(), kept.end(), "box"));
  EXPECT_EQ(world.modelNames(), kept);
  const std::vector<std::string> warnings = world.takeWarnings();
  if (GetParam() == "dart") {
    EXPECT_EQ(stepped.code, StatusCode::EngineFault) << stepped;
    EXPECT_NE(stepped.subject.find("injected failure"), std::string::npos) << stepped.subject;
  } else if (GetParam() == "ode") {  // the exact dWorldStep, retaken with dWorldQuickStep
    EXPECT_TRUE(stepped.ok()) << stepped;
    EXPECT_EQ(world.timeNs(), start_ns + std::llround(world.params().step * 1e9));
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("taken again"), std::string::npos) << warnings[0];
    EXPECT_NE(warnings[0].find("injected failure"), std::string::npos) << warnings[0];
  } else {
    EXPECT_EQ(stepped.code, StatusCode::EngineFaultUnattributed) << stepped;
    EXPECT_NE(stepped.subject.find("injected failure"), std::string::npos) << stepped.subject;
    EXPECT_EQ(world.timeNs(), start_ns);
    Pose after;
    ASSERT_TRUE(world.modelState("box", "", &after, &twist).ok());
    EXPECT_EQ(after.position.z, before.position.z);
  }
  for (int i = 0; i < 100; ++i) ASSERT_TRUE(world.step().ok());
  EXPECT_EQ(world.modelNames(), kept);
}

INSTANTIATE_TEST_SUITE_P(Engines, EngineFaultOn, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

// When the failed step cannot be taken again, the model it involves is removed: the one model
// whose bodies were in its contacts (the box on the ground; the pendulum and the victim swing
// and fall in the air), never one merely spawned last. With two models in touch (the victim
// landed, a second box) the engine cannot tell, and the world stops where the step started
// with every model.
TEST(EngineFault, OdeFailureIsPinnedOnTheOneModelInItsContactsElseTheWorldStops) {
  World world("ode");
  populate(&world, true);
  settledNames(&world);
  WorldTestAccess::failNextStep(world, true, false);
  const Status removed = world.step();
  EXPECT_EQ(removed.code, StatusCode::EngineFault) << removed;
  EXPECT_EQ(world.modelNames(), (std::vector<std::string>{"ground_plane", "pendulum", "victim"}));
  const std::vector<std::string> warnings = world.takeWarnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("'box'"), std::string::npos) << warnings[0];

  ASSERT_TRUE(world.spawn("box2", kBox, ModelFormat::Urdf, at(3, 0.3)).ok());
  for (int i = 0; i < 1500; ++i) ASSERT_TRUE(world.step().ok());  // both land; the victim too
  const int64_t start_ns = world.timeNs();
  Pose before, after;
  Twist twist;
  ASSERT_TRUE(world.modelState("victim", "", &before, &twist).ok());
  WorldTestAccess::failNextStep(world, true, false);
  const Status stopped = world.step();
  EXPECT_EQ(stopped.code, StatusCode::EngineFaultUnattributed) << stopped;
  EXPECT_NE(stopped.subject.find("'victim', 'box2'"), std::string::npos) << stopped.subject;
  EXPECT_EQ(world.modelNames(),
            (std::vector<std::string>{"ground_plane", "pendulum", "victim", "box2"}));
  EXPECT_EQ(world.timeNs(), start_ns);
  ASSERT_TRUE(world.modelState("victim", "", &after, &twist).ok());
  EXPECT_EQ(after.position.x, before.position.x);
  EXPECT_EQ(after.position.z, before.position.z);
  for (int i = 0; i < 100; ++i) ASSERT_TRUE(world.step().ok());
}

// A ray query the engine fails inside: refused (EngineFault), the engine rebuilt with every model
// where it was, and the next query answered.
TEST_P(EngineFaultOn, AFailedRayQueryRebuildsTheEngineWithEveryModelInPlace) {
  World world(GetParam());
  ASSERT_TRUE(world.spawn("box", kBox, ModelFormat::Urdf, at(2, 0.5)).ok());
  Pose before, after;
  Twist twist;
  ASSERT_TRUE(world.modelState("box", "", &before, &twist).ok());
  WorldTestAccess::failNextStep(world, false, false);
  std::vector<double> distances{1};
  const std::vector<Ray> ray{{{0, before.position.y, before.position.z}, {1, 0, 0}, 10}};
  const Status failed = world.castRays(ray, &distances);
  EXPECT_EQ(failed.code, StatusCode::EngineFault) << failed;
  EXPECT_TRUE(distances.empty());
  EXPECT_EQ(world.takeWarnings().size(), 1u);
  ASSERT_TRUE(world.modelState("box", "", &after, &twist).ok());
  EXPECT_EQ(after.position.x, before.position.x);
  EXPECT_EQ(after.position.z, before.position.z);
  ASSERT_TRUE(world.castRays(ray, &distances).ok());
  ASSERT_EQ(distances.size(), 1u);
  EXPECT_NEAR(distances[0], before.position.x - 0.05, 1e-6);  // the 0.1 m box's near face
}

}  // namespace
}  // namespace onedof_sim
