// The update gates over sim time: each of Gazebo's rules for when an update is due, at a rate of
// sim time, kept to exactly (integer ns).
#pragma once

#include <cmath>
#include <cstdint>

namespace onedof_sim::plugins {

// The update-rate gate of Gazebo's model plugins (gazebo_ros_diff_drive, _joint_state_publisher,
// _p3d): an update is due once more than a period has passed since the last one, and the last
// one then moves on by exactly a period, so that updates keep to the rate's grid whatever the
// step. A rate of 0 or less: every step. Sim time going back (reset_simulation) starts the gate
// over there.
class UpdateGate {
 public:
  UpdateGate() = default;
  UpdateGate(double rate_hz, int64_t now_ns)
      : period_ns_(rate_hz > 0 ? std::llround(1e9 / rate_hz) : 0), last_ns_(now_ns) {}

  // Whether an update is due at `now_ns`; if so it counts as made, and *elapsed_ns (if given) is
  // the sim time since the last one.
  bool due(int64_t now_ns, int64_t* elapsed_ns = nullptr) {
    if (now_ns < last_ns_) last_ns_ = now_ns;
    const int64_t elapsed = now_ns - last_ns_;
    if (elapsed <= period_ns_) return false;
    if (elapsed_ns) *elapsed_ns = elapsed;
    last_ns_ += period_ns_;
    return true;
  }

  // The next period starts at `now_ns` (a plugin's reset).
  void restart(int64_t now_ns) { last_ns_ = now_ns; }

 private:
  int64_t period_ns_ = 0;
  int64_t last_ns_ = 0;
};

// When a sensor updates, as Gazebo's Sensor::Update decides over sim time: at a time later than
// the last update, once the time since it, plus what the last update came late, reaches the
// period (1 / update_rate), so that updates keep to the rate's grid whatever the step; a rate of
// 0: every step. The last update starts at time 0, as Gazebo's does, and goes back there on a
// reset (Gazebo's ResetLastUpdateTime): after reset_world the next step updates, after
// reset_simulation the step that reaches a period.
class SensorGate {
 public:
  SensorGate() = default;
  explicit SensorGate(double rate_hz)
      : period_ns_(rate_hz > 0 ? static_cast<int64_t>(std::llround(1e9 / rate_hz)) : 0) {}

  // Whether an update is due at `now_ns`; if so it counts as made.
  bool due(int64_t now_ns) {
    if (now_ns < last_ns_) reset();
    if (now_ns <= last_ns_) return false;
    const int64_t elapsed = period_ns_ > 0 ? now_ns - last_ns_ + delay_ns_ : 0;
    if (elapsed < period_ns_) return false;
    delay_ns_ = elapsed - period_ns_;
    if (delay_ns_ > period_ns_) delay_ns_ = 0;  // too far behind to catch up
    last_ns_ = now_ns;
    return true;
  }

  void reset() {
    last_ns_ = 0;
    delay_ns_ = 0;
  }

 private:
  int64_t period_ns_ = 0;
  int64_t last_ns_ = 0;
  int64_t delay_ns_ = 0;
};

// The plugin's own <updateRate> over its sensor's updates, as GazeboRosCameraUtils throttles:
// an update goes out once the sim time since the last one that went out is at least the period
// (the last starting at 0); a rate of 0: every update.
class PublishThrottle {
 public:
  PublishThrottle() = default;
  explicit PublishThrottle(double rate_hz)
      : period_ns_(rate_hz > 0 ? static_cast<int64_t>(std::llround(1e9 / rate_hz)) : 0) {}
  bool due(int64_t now_ns) {
    if (now_ns < last_ns_) last_ns_ = now_ns;  // sim time went back (reset_simulation)
    if (now_ns - last_ns_ < period_ns_) return false;
    last_ns_ = now_ns;
    return true;
  }
  void reset() { last_ns_ = 0; }

 private:
  int64_t period_ns_ = 0;
  int64_t last_ns_ = 0;
};

}  // namespace onedof_sim::plugins
