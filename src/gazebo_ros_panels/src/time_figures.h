// The figures of Gazebo's bottom bar from the simulator's clock: sim time, real time, the
// real-time factor and the iterations. No ROS, no Qt: fed with (sim time, wall time) samples.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <utility>

namespace gazebo_ros_panels {

class TimeFigures {
 public:
  // One clock reading: the sim time and the wall time it was received at. A sim time below the
  // last one is a reset_simulation: real time and iterations start again from it.
  void clock(int64_t sim_ns, int64_t wall_ns);
  // The physics step (s) the iterations are counted in; the simulator steps by exactly it.
  void stepSize(double seconds);

  bool seen() const { return seen_; }
  double simSeconds() const { return sim_ns_ * 1e-9; }
  // Wall time at now_wall_ns since the first reading or the last reset (Gazebo's real time runs
  // on while paused).
  double realSeconds(int64_t now_wall_ns) const;
  // Sim time over wall time across the last second of readings; 0 once no reading came for a
  // second (paused, or no simulator).
  double realTimeFactor(int64_t now_wall_ns) const;
  uint64_t iterations() const { return iterations_; }

 private:
  bool seen_ = false;
  int64_t sim_ns_ = 0;
  int64_t real_start_wall_ns_ = 0;
  int64_t step_ns_ = 0;
  uint64_t iterations_ = 0;
  std::deque<std::pair<int64_t, int64_t>> window_;  // (sim, wall) of the last second
};

// Gazebo's format for its times: "dd hh:mm:ss.mmm".
std::string gazeboTimeText(double seconds);

}  // namespace gazebo_ros_panels
