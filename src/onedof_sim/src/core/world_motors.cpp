// Velocity motors on joints (World::setJointVelocityCommand): the engine's own joint motor, in
// its constraint solver, for one step at a time.
//
// A motor solved with the step is what keeps a driven wheel stable: the solver finds the effort
// (within its bound) that gives the joint the commanded rate at the end of the step, whatever
// the wheel carries or touches. An effort computed before the step from the rate error could only
// use the wheel's own inertia, and would overshoot by the whole robot's weight on it.
#include <algorithm>
#include <cmath>

#include "world_impl.h"

namespace onedof_sim {

using namespace core;

Status World::setJointVelocityCommand(const std::string& joint_name, double velocity,
                                      double max_effort) {
  ModelRecord* model;
  size_t index;
  if (!impl_->findJoint(joint_name, &model, &index)) return {StatusCode::JointNotFound, joint_name};
  const JointRecord& joint = model->joints[index];
  if (joint.engine_joint < 0) return {StatusCode::JointIsFixed, joint_name};
  if (!std::isfinite(velocity)) return {StatusCode::NotFinite, "velocity"};
  if (!std::isfinite(max_effort)) return {StatusCode::NotFinite, "max_effort"};
  if (max_effort < 0) return {StatusCode::InvalidParameter, "max_effort"};
  const double cap = joint.desc.type == JointType::Prismatic ? kMaxLinearSpeed
                                                             : maxAngularSpeed(impl_->params.step);
  if (std::abs(velocity) > cap) return outOfRange("velocity", -cap, cap);
  max_effort = std::min(max_effort, joint.desc.effort_limit);
  auto& motors = impl_->joint_motors;
  auto same = std::find_if(motors.begin(), motors.end(), [&](const JointMotorCommand& c) {
    return c.model == model && c.joint == index;
  });
  if (same == motors.end()) motors.push_back({model, index, velocity, max_effort});
  else *same = {model, index, velocity, max_effort};  // the latest command for the step wins
  return {};
}

void World::Impl::applyMotors() {
  for (const JointMotorCommand& motor : joint_motors) {
    if (motor.model->blown_up || motor.max_effort <= 0) continue;
    motor.model->engine_model->setJointMotor(motor.model->joints[motor.joint].engine_joint,
                                             motor.velocity, motor.max_effort);
  }
}

void World::Impl::releaseMotors() {
  for (const JointMotorCommand& motor : joint_motors)
    motor.model->engine_model->setJointMotor(motor.model->joints[motor.joint].engine_joint, 0, 0);
}

}  // namespace onedof_sim
