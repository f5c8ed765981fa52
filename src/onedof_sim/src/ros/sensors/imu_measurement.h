// What an IMU on a link measures, the one implementation behind libgazebo_ros_imu.so (a model
// plugin) and the `imu` sensor (gazebo_ros_imu_sensor): the orientation of its frame in the
// world, its angular velocity and the specific force an accelerometer feels (the acceleration of
// the frame's origin minus gravity: at rest |g| up), both in the frame's axes, as Gazebo's
// ImuSensor computes them.
//
// The acceleration is the change of the origin's world velocity between two measurements over
// the sim time between them (Gazebo's finite difference); the origin's velocity is the link's
// plus its angular velocity crossed with the lever from the link's origin. A measurement at the
// same time as the last, or before the first, keeps the last acceleration.
#pragma once

#include <cstdint>
#include <string>

#include <onedof_sim/world.h>

#include "sensor_noise.h"

namespace onedof_sim::plugins {

struct ImuReading {
  Quat orientation;          // the frame in the world
  Vec3 angular_velocity;     // rad/s, in the frame's axes
  Vec3 linear_acceleration;  // m/s^2, specific force (gravity's reaction included), frame's axes
};

class ImuMeasurement {
 public:
  ImuMeasurement() = default;
  // link: scoped "model::link"; on_link: the frame's pose on the link; world_turn: a turn of the
  // frame given on the world's side (the frame's orientation is world_turn * link * on_link),
  // as gazebo_ros_imu's rpyOffset turns it.
  ImuMeasurement(std::string link, const Pose& on_link, const Quat& world_turn = {});

  // The velocity the next acceleration differences from: the frame's now. False when the world
  // has no such link.
  bool restart(const World& world, int64_t time_ns);
  // A measurement at the world's present state, at `time_ns`; false when the world has no such
  // link (nothing is changed then).
  bool measure(const World& world, int64_t time_ns, ImuReading* reading);

  const std::string& link() const { return link_; }

 private:
  // The frame's pose in the world and its origin's world velocity.
  bool frameState(const World& world, Pose* frame, Vec3* velocity, Vec3* angular) const;

  std::string link_;
  Pose on_link_;
  Quat world_turn_;
  int64_t last_time_ns_ = 0;
  Vec3 last_velocity_;
  Vec3 acceleration_;
};

// The `imu` sensor's noise, one model a component: rates x, y, z, then accelerations x, y, z.
struct ImuNoiseParams {
  NoiseParams rate[3], acceleration[3];
  bool any() const;
  bool drifts() const;  // any has a dynamic bias
};

// Reads the noise of the <imu> of a <sensor> element (its XML text): <angular_velocity> and
// <linear_acceleration> <x>/<y>/<z> <noise>, and SDF 1.4's <imu><noise> (<type>, <rate> and
// <accel> with mean, stddev, bias_mean, bias_stddev), which stands for the same noise on each
// axis as sdformat's conversion makes it (the per-axis elements, when there are any, win). No
// <imu>: no noise. False, with *error naming the element, when one is malformed.
bool readImuNoise(const std::string& sensor_xml, ImuNoiseParams* params, std::string* error);

}  // namespace onedof_sim::plugins
