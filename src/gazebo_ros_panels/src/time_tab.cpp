#include "time_tab.h"

#include <QFormLayout>
#include <QHBoxLayout>
#include <QVBoxLayout>

#include "gui_thread.h"

namespace gazebo_ros_panels {

TimeTab::TimeTab(GazeboClient* client, std::function<void(const QString&)> report,
                 std::function<void()> physics_changed, QWidget* parent)
    : QWidget(parent),
      client_(client),
      report_(std::move(report)),
      physics_changed_(std::move(physics_changed)) {
  play_ = new QPushButton("Pa&use");
  step_ = new QPushButton("St&ep");
  step_count_ = new QSpinBox;
  step_count_->setRange(1, 1000000);
  step_count_->setToolTip("steps per click (the simulator's /gazebo/step_simulation)");
  sim_time_ = new QLabel("-");
  real_time_ = new QLabel("-");
  real_time_->setToolTip("wall time since this panel first saw the clock or since Reset Time");
  factor_ = new QLabel("-");
  iterations_ = new QLabel("-");
  frame_rate_ = new QLabel("-");
  frame_rate_->setToolTip("frames the 3D view drew in the last second");
  auto* reset_time = new QPushButton("&Reset Time");
  auto* reset_world = new QPushButton("Reset W&orld");

  auto* buttons = new QHBoxLayout;
  buttons->addWidget(play_);
  buttons->addWidget(step_);
  buttons->addWidget(step_count_);
  auto* figures = new QFormLayout;
  figures->addRow("Sim time", sim_time_);
  figures->addRow("Real time", real_time_);
  figures->addRow("Real time factor", factor_);
  figures->addRow("Iterations", iterations_);
  figures->addRow("FPS", frame_rate_);
  auto* resets = new QHBoxLayout;
  resets->addWidget(reset_time);
  resets->addWidget(reset_world);
  auto* layout = new QVBoxLayout(this);
  layout->addLayout(buttons);
  layout->addLayout(figures);
  layout->addLayout(resets);
  layout->addStretch();

  auto then_physics = [this](const Outcome&) { physics_changed_(); };
  connect(play_, &QPushButton::clicked, this, [this, then_physics] {
    if (paused_)
      client_->unpause(reportOnGui(this, report_, then_physics));
    else
      client_->pause(reportOnGui(this, report_, then_physics));
  });
  connect(step_, &QPushButton::clicked, this, [this, then_physics] {
    client_->step(static_cast<uint64_t>(step_count_->value()),
                  reportOnGui(this, report_, then_physics));
  });
  connect(reset_time, &QPushButton::clicked, this, [this] {
    client_->resetSimulation(reportOnGui(this, report_));
  });
  connect(reset_world, &QPushButton::clicked, this, [this] {
    client_->resetWorld(reportOnGui(this, report_));
  });
}

void TimeTab::showPhysics(const PhysicsState& state) {
  paused_ = state.paused;
  play_->setText(paused_ ? "Pl&ay" : "Pa&use");
  figures_.stepSize(state.time_step);
}

void TimeTab::showClock(const ClockReading& clock, int64_t now_wall_ns) {
  if (clock.seen && clock.count != clock_count_) {
    clock_count_ = clock.count;
    figures_.clock(clock.sim_ns, clock.wall_ns);
  }
  if (!figures_.seen()) return;
  sim_time_->setText(QString::fromStdString(gazeboTimeText(figures_.simSeconds())));
  real_time_->setText(QString::fromStdString(gazeboTimeText(figures_.realSeconds(now_wall_ns))));
  factor_->setText(QString::number(figures_.realTimeFactor(now_wall_ns), 'f', 2));
  iterations_->setText(QString::number(figures_.iterations()));
}

void TimeTab::showFrameRate(double frames_per_second) {
  frame_rate_->setText(QString::number(frames_per_second, 'f', 0));
}

}  // namespace gazebo_ros_panels
