// The update-rate gate of Gazebo's model plugins (gazebo_ros_diff_drive, _joint_state_publisher,
// _p3d), over sim time: an update is due once more than a period has passed since the last one,
// and the last one then moves on by exactly a period, so that updates keep to the rate's grid
// whatever the step. A rate of 0 or less: every step. Sim time going back (reset_simulation)
// starts the gate over there.
#pragma once

#include <cmath>
#include <cstdint>

namespace onedof_sim::plugins {

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

}  // namespace onedof_sim::plugins
