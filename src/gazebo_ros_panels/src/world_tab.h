// Gazebo's World tab: the models with their links and joints as a tree, the chosen model's pose
// (typing one and applying it moves the model: set_model_state), and the physics (step size,
// real-time factor target, gravity: get/set_physics_properties). The tree's chosen model is the
// window's selection (Selection::hub()), as Gazebo's World tab and scene select together: a model
// chosen in the tree (by mouse, or by keys: Alt+D, then its name typed) is selected in the view,
// and one selected in the view is chosen in the tree.
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
  void choose(const QString& model);  // the tree's current item, as the selection says
  void showChosenPose(const gazebo_msgs::ModelStates& states);  // in the pose fields
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
  bool choosing_ = false;  // the tree's current item being set from the selection
  std::array<QDoubleSpinBox*, 6> pose_;  // x y z (m), roll pitch yaw (deg)
  QDoubleSpinBox* step_size_;
  QDoubleSpinBox* factor_target_;
  std::array<QDoubleSpinBox*, 3> gravity_;
};

}  // namespace gazebo_ros_panels
