// Gazebo's World tab: the models with their links and joints as a tree, the chosen model's pose
// (typing one and applying it moves the model: set_model_state), and the physics (step size,
// real-time factor target, gravity: get/set_physics_properties).
#pragma once

#include <QDoubleSpinBox>
#include <QTreeWidget>
#include <QWidget>

#include <array>
#include <functional>
#include <set>
#include <string>

#include "gazebo_client.h"

namespace gazebo_ros_panels {

class WorldTab : public QWidget {
  Q_OBJECT
 public:
  WorldTab(GazeboClient* client, std::function<void(const QString&)> report,
           std::function<void()> physics_changed, QWidget* parent = nullptr);
  void showPhysics(const PhysicsState& state);
  void showModelStates(const gazebo_msgs::ModelStates& states);

 private:
  std::string chosenModel() const;
  void applyPose();
  void applyPhysics();

  GazeboClient* client_;
  std::function<void(const QString&)> report_;
  std::function<void()> physics_changed_;
  std::set<std::string> listed_;  // the models the tree was last asked for
  bool tree_pending_ = false;
  PhysicsState physics_;
  bool physics_known_ = false;
  QTreeWidget* tree_;
  std::array<QDoubleSpinBox*, 6> pose_;  // x y z (m), roll pitch yaw (deg)
  QDoubleSpinBox* step_size_;
  QDoubleSpinBox* factor_target_;
  std::array<QDoubleSpinBox*, 3> gravity_;
};

}  // namespace gazebo_ros_panels
