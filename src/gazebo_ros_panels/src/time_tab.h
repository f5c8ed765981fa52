// Gazebo's bottom bar and Edit menu's resets: play/pause, step with a count, sim time, real time,
// real-time factor, iterations, the view's frames per second, reset time, reset world.
#pragma once

#include <QLabel>
#include <QPushButton>
#include <QSpinBox>
#include <QWidget>

#include <functional>

#include "gazebo_client.h"
#include "time_figures.h"

namespace gazebo_ros_panels {

class TimeTab : public QWidget {
  Q_OBJECT
 public:
  TimeTab(GazeboClient* client, std::function<void(const QString&)> report,
          std::function<void()> physics_changed, QWidget* parent = nullptr);
  void showPhysics(const PhysicsState& state);  // the pause state and the step size
  void showClock(const ClockReading& clock, int64_t now_wall_ns);
  void showFrameRate(double frames_per_second);

 private:
  GazeboClient* client_;
  std::function<void(const QString&)> report_;
  std::function<void()> physics_changed_;  // asks for the physics again after a change
  TimeFigures figures_;
  uint64_t clock_count_ = 0;
  bool paused_ = false;
  QPushButton* play_;
  QPushButton* step_;
  QSpinBox* step_count_;
  QLabel* sim_time_;
  QLabel* real_time_;
  QLabel* factor_;
  QLabel* iterations_;
  QLabel* frame_rate_;
};

}  // namespace gazebo_ros_panels
