#include "imu_measurement.h"

#include <utility>

#include <onedof_sim/pose_math.h>

namespace onedof_sim::plugins {

ImuMeasurement::ImuMeasurement(std::string link, const Pose& on_link, const Quat& world_turn)
    : link_(std::move(link)), on_link_(on_link), world_turn_(world_turn) {}

bool ImuMeasurement::frameState(const World& world, Pose* frame, Vec3* velocity,
                                Vec3* angular) const {
  Pose link_pose;
  Twist twist;
  if (!world.linkState(link_, "", &link_pose, &twist).ok()) return false;
  *frame = compose(link_pose, on_link_);
  const Vec3 lever{frame->position.x - link_pose.position.x,
                   frame->position.y - link_pose.position.y,
                   frame->position.z - link_pose.position.z};
  const Vec3& w = twist.angular;
  *velocity = {twist.linear.x + (w.y * lever.z - w.z * lever.y),
               twist.linear.y + (w.z * lever.x - w.x * lever.z),
               twist.linear.z + (w.x * lever.y - w.y * lever.x)};
  *angular = w;
  return true;
}

bool ImuMeasurement::restart(const World& world, int64_t time_ns) {
  Pose frame;
  Vec3 velocity, angular;
  if (!frameState(world, &frame, &velocity, &angular)) return false;
  last_time_ns_ = time_ns;
  last_velocity_ = velocity;
  acceleration_ = {};
  return true;
}

bool ImuMeasurement::measure(const World& world, int64_t time_ns, ImuReading* reading) {
  Pose frame;
  Vec3 velocity, angular;
  if (!frameState(world, &frame, &velocity, &angular)) return false;
  const double dt = 1e-9 * static_cast<double>(time_ns - last_time_ns_);
  if (dt > 0) {
    acceleration_ = {(velocity.x - last_velocity_.x) / dt, (velocity.y - last_velocity_.y) / dt,
                     (velocity.z - last_velocity_.z) / dt};
    last_time_ns_ = time_ns;
    last_velocity_ = velocity;
  }
  const Vec3& g = world.params().gravity;
  const Vec3 specific_force{acceleration_.x - g.x, acceleration_.y - g.y, acceleration_.z - g.z};
  reading->orientation = normalized(multiply(world_turn_, frame.orientation));
  reading->angular_velocity = inFrame(reading->orientation, angular);
  reading->linear_acceleration = inFrame(reading->orientation, specific_force);
  return true;
}

}  // namespace onedof_sim::plugins
