// The sensor_msgs/Imu both IMU plugins publish (libgazebo_ros_imu.so and the imu sensor's
// gazebo_ros_imu_sensor): a reading, its noise already added, stamped in a frame, with each
// covariance's diagonal set to one variance.
#pragma once

#include <cstdint>
#include <string>

#include <sensor_msgs/Imu.h>

#include "conversions.h"
#include "sensors/imu_measurement.h"

namespace onedof_sim::plugins {

inline sensor_msgs::Imu imuMessage(const ImuReading& reading, int64_t time_ns,
                                   const std::string& frame, double variance) {
  sensor_msgs::Imu msg;
  msg.header.stamp.fromNSec(static_cast<uint64_t>(time_ns));
  msg.header.frame_id = frame;
  msg.orientation = toQuaternion(reading.orientation);
  msg.angular_velocity = toVector3(reading.angular_velocity);
  msg.linear_acceleration = toVector3(reading.linear_acceleration);
  for (int i : {0, 4, 8})
    msg.orientation_covariance[i] = msg.angular_velocity_covariance[i] =
        msg.linear_acceleration_covariance[i] = variance;
  return msg;
}

}  // namespace onedof_sim::plugins
