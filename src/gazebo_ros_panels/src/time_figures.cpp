#include "time_figures.h"

#include <cmath>
#include <cstdio>

namespace gazebo_ros_panels {
namespace {
constexpr int64_t kWindowNs = 1000000000;
}

void TimeFigures::stepSize(double seconds) {
  // The count so far stays; from here on the new step counts (set_physics_properties). The first
  // step size known counts the steps of the sim time already read.
  const int64_t step_ns = seconds > 0 ? std::llround(seconds * 1e9) : 0;
  if (seen_ && step_ns_ <= 0 && step_ns > 0)
    iterations_ = static_cast<uint64_t>(std::llround(double(sim_ns_) / step_ns));
  step_ns_ = step_ns;
}

void TimeFigures::clock(int64_t sim_ns, int64_t wall_ns) {
  if (!seen_ || sim_ns < sim_ns_) {
    real_start_wall_ns_ = wall_ns;
    window_.clear();
    iterations_ = step_ns_ > 0 ? static_cast<uint64_t>(std::llround(double(sim_ns) / step_ns_)) : 0;
  } else if (step_ns_ > 0) {
    iterations_ += static_cast<uint64_t>(std::llround(double(sim_ns - sim_ns_) / step_ns_));
  }
  seen_ = true;
  sim_ns_ = sim_ns;
  window_.emplace_back(sim_ns, wall_ns);
  while (window_.size() > 2 && window_.back().second - window_[1].second >= kWindowNs)
    window_.pop_front();
}

double TimeFigures::realSeconds(int64_t now_wall_ns) const {
  return seen_ ? (now_wall_ns - real_start_wall_ns_) * 1e-9 : 0;
}

double TimeFigures::realTimeFactor(int64_t now_wall_ns) const {
  if (window_.size() < 2 || now_wall_ns - window_.back().second >= kWindowNs) return 0;
  const int64_t wall = window_.back().second - window_.front().second;
  if (wall <= 0) return 0;
  return double(window_.back().first - window_.front().first) / double(wall);
}

std::string gazeboTimeText(double seconds) {
  if (!(seconds >= 0)) seconds = 0;
  const int64_t ms = std::llround(seconds * 1000);
  char text[48];
  std::snprintf(text, sizeof text, "%02lld %02lld:%02lld:%02lld.%03lld",
                static_cast<long long>(ms / 86400000), static_cast<long long>(ms / 3600000 % 24),
                static_cast<long long>(ms / 60000 % 60), static_cast<long long>(ms / 1000 % 60),
                static_cast<long long>(ms % 1000));
  return text;
}

}  // namespace gazebo_ros_panels
