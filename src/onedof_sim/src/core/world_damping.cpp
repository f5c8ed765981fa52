// Joint damping, applied by the world as an effort on the joint, alike on every engine, and taken
// implicitly so that it is stable at any accepted value.
//
// An explicit effort -b qdot changes the joint's speed by a factor 1 - b dt / I per step: past
// b = 2 I / dt (700 N m s/rad for the tutorial's link at 1 ms) every step reverses the joint with
// a larger speed and it swings itself apart. Backward Euler on the joint's own coordinate,
//   I (qdot' - qdot) = dt (Q - b qdot'),   so   -b qdot' = -b (I qdot + dt Q) / (I + b dt),
// scales the speed by I / (I + b dt), never below 0 with I at most the true inertia, and leaves
// the speed under a steady force Q tending to Q / b at any b, as a damper's does. Q is what the
// world knows before the step (gravity and the joint's own effort); a force it cannot know there
// (contacts, the pull of other joints) meets a damping of b I / (I + b dt), at most I / dt. At
// rest under no net force the damping is zero, so it never moves a joint's balance.
#include <cmath>

#include "world_impl.h"

namespace onedof_sim {

using namespace core;

namespace {

// I1 I2 / (I1 + I2): the inertia of a relative coordinate between two free bodies.
double reduced(double a, double b) { return a * b / (a + b); }

}  // namespace

double World::Impl::dampingInertia(const ModelRecord& model, const JointRecord& joint) const {
  const int child = model.links[joint.child].body;
  const int parent = joint.parent < 0 ? -1 : model.links[joint.parent].body;
  const BodySpec& child_mass = model.bodies[child];
  if (joint.desc.type == JointType::Prismatic)
    return parent < 0 ? child_mass.mass : reduced(child_mass.mass, model.bodies[parent].mass);
  const JointFrame frame = jointFrame(model, joint);
  auto aboutCom = [&](int body) {
    const Pose pose = model.engine_model->bodyPose(body);
    return momentAbout(model.bodies[body], rotate(conjugate(pose.orientation), frame.axis));
  };
  if (parent >= 0) return reduced(aboutCom(child), aboutCom(parent));
  const Vec3 arm = model.engine_model->bodyPose(child).position - frame.anchor;
  const double along = dot(arm, frame.axis);
  return aboutCom(child) + child_mass.mass * (dot(arm, arm) - along * along);
}

double World::Impl::gravityOnJoint(const ModelRecord& model, const JointRecord& joint) const {
  const bool prismatic = joint.desc.type == JointType::Prismatic;
  const JointFrame frame = jointFrame(model, joint);
  double force = 0;
  for (int body : joint.moved_bodies) {
    const BodySpec& mass = model.bodies[body];
    if (!mass.gravity) continue;
    const Vec3 weight = mass.mass * params.gravity;
    const Vec3 arm = model.engine_model->bodyPose(body).position - frame.anchor;
    force += prismatic ? dot(frame.axis, weight) : dot(frame.axis, cross(arm, weight));
  }
  return force;
}

void World::Impl::applyDamping(const std::vector<JointEffortSum>& efforts) {
  const double dt = params.step;
  for (const auto& model : models)
    for (size_t index = 0; index < model->joints.size(); ++index) {
      const JointRecord& joint = model->joints[index];
      const double damping = joint.desc.damping;
      if (joint.engine_joint < 0 || damping == 0) continue;
      double known_force = gravityOnJoint(*model, joint);
      for (const JointEffortSum& sum : efforts)
        if (sum.model == model.get() && sum.joint == index) known_force += sum.effort;
      const double inertia = dampingInertia(*model, joint);
      const double effort = -damping * (inertia * jointRate(*model, joint) + dt * known_force) /
                            (inertia + damping * dt);
      model->engine_model->addJointEffort(joint.engine_joint, effort);
    }
}

}  // namespace onedof_sim
