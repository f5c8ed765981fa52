#include "world_tab.h"

#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QPushButton>
#include <QVBoxLayout>
#include <tf2/LinearMath/Matrix3x3.h>
#include <tf2/LinearMath/Quaternion.h>

#include <algorithm>
#include <cmath>

#include "gui_thread.h"
#include "number_field.h"
#include "selection.h"

namespace gazebo_ros_panels {
namespace {

constexpr double kDegrees = 180.0 / M_PI;

bool anyHasFocus(const QDoubleSpinBox* const* boxes, size_t count) {
  for (size_t i = 0; i < count; ++i)
    if (boxes[i]->hasFocus()) return true;
  return false;
}

}  // namespace

WorldTab::WorldTab(GazeboClient* client, std::function<void(const QString&)> report,
                   std::function<void()> physics_changed, QWidget* parent)
    : QWidget(parent),
      client_(client),
      report_(std::move(report)),
      physics_changed_(std::move(physics_changed)) {
  tree_ = new QTreeWidget;
  tree_->setHeaderLabel("Models");

  auto* pose_group = new QGroupBox("Pose of the chosen model (world frame)");
  auto* pose_form = new QFormLayout;
  const char* names[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
  for (size_t i = 0; i < 6; ++i) {
    pose_[i] = i < 3 ? numberField(-1e5, 1e5, 4, " m")  // x y z
                     : numberField(-180, 180, 2, " deg");  // roll pitch yaw
    pose_form->addRow(names[i], pose_[i]);
  }
  auto* apply_pose = new QPushButton("M&ove");
  pose_form->addRow(apply_pose);
  pose_group->setLayout(pose_form);

  auto* physics_group = new QGroupBox("Physics");
  auto* physics_form = new QFormLayout;
  step_size_ = numberField(1e-6, 1, 6, " s");
  factor_target_ = numberField(0, 1e6, 3, "");
  factor_target_->setToolTip("real time update rate x step size; 0 runs as fast as it can");
  physics_form->addRow("max step size", step_size_);
  physics_form->addRow("real time factor", factor_target_);
  const char* axes[3] = {"gravity x", "gravity y", "gravity z"};
  for (size_t i = 0; i < 3; ++i) {
    gravity_[i] = numberField(-1e4, 1e4, 4, " m/s²");
    physics_form->addRow(axes[i], gravity_[i]);
  }
  auto* apply_physics = new QPushButton("Set ph&ysics");
  physics_form->addRow(apply_physics);
  physics_group->setLayout(physics_form);

  auto* models = new QLabel("Mo&dels");
  models->setBuddy(tree_);
  auto* layout = new QVBoxLayout(this);
  layout->addWidget(models);
  layout->addWidget(tree_, 1);
  layout->addWidget(pose_group);
  layout->addWidget(physics_group);

  connect(apply_pose, &QPushButton::clicked, this, &WorldTab::applyPose);
  connect(apply_physics, &QPushButton::clicked, this, &WorldTab::applyPhysics);
  connect(tree_, &QTreeWidget::currentItemChanged, this, [this] {
    showChosenPose(client_->modelStates());  // at once: Move moves what the tree shows
    if (!choosing_) Selection::hub().select(QString::fromStdString(chosenModel()));
  });
  connect(&Selection::hub(), &Selection::changed, this, &WorldTab::choose);
}

void WorldTab::choose(const QString& model) {
  const QList<QTreeWidgetItem*> found = tree_->findItems(model, Qt::MatchExactly);  // models
  QTreeWidgetItem* item = model.isEmpty() || found.isEmpty() ? nullptr : found.front();
  if (QString::fromStdString(chosenModel()) == model && (item || model.isEmpty())) return;
  choosing_ = true;
  tree_->setCurrentItem(item);
  choosing_ = false;
}

std::string WorldTab::chosenModel() const {
  const QTreeWidgetItem* item = tree_->currentItem();
  while (item && item->parent()) item = item->parent();
  return item ? item->text(0).toStdString() : std::string();
}

void WorldTab::showModelStates(const gazebo_msgs::ModelStates& states) {
  const std::set<std::string> names(states.name.begin(), states.name.end());
  if (names != listed_ && !tree_pending_) {
    listed_ = names;
    tree_pending_ = true;
    client_->modelTrees([this](const Outcome& outcome, const std::vector<ModelTree>& trees) {
      onGuiThread(this, [this, outcome, trees] {
        tree_pending_ = false;
        if (!outcome.ok) {
          listed_.clear();  // asked again with the next states
          report_(QString::fromStdString(outcome.text));
          return;
        }
        // The selection stays chosen; a model selected in the view before the tree listed it is
        // chosen now, and a selected model the world no longer has is selected no more.
        const QString chosen = Selection::hub().model();
        choosing_ = true;
        tree_->clear();
        for (const ModelTree& model : trees) {
          auto* item = new QTreeWidgetItem(tree_, {QString::fromStdString(model.name)});
          auto* links = new QTreeWidgetItem(item, {"links"});
          for (const std::string& link : model.links)
            new QTreeWidgetItem(links, {QString::fromStdString(link)});
          auto* joints = new QTreeWidgetItem(item, {"joints"});
          for (const std::string& joint : model.joints)
            new QTreeWidgetItem(joints, {QString::fromStdString(joint)});
          if (QString::fromStdString(model.name) == chosen) tree_->setCurrentItem(item);
        }
        choosing_ = false;
        const std::vector<std::string> now = client_->modelStates().name;
        if (std::find(now.begin(), now.end(), chosen.toStdString()) == now.end())
          Selection::hub().select("");
      });
    });
  }
  if (anyHasFocus(pose_.data(), pose_.size())) return;  // the user is typing a pose
  showChosenPose(states);
}

void WorldTab::showChosenPose(const gazebo_msgs::ModelStates& states) {
  const std::string chosen = chosenModel();
  for (size_t i = 0; i < states.name.size() && i < states.pose.size(); ++i) {
    if (states.name[i] != chosen) continue;
    const geometry_msgs::Pose& pose = states.pose[i];
    double roll, pitch, yaw;
    tf2::Matrix3x3(tf2::Quaternion(pose.orientation.x, pose.orientation.y, pose.orientation.z,
                                   pose.orientation.w))
        .getRPY(roll, pitch, yaw);
    const double values[6] = {pose.position.x, pose.position.y, pose.position.z,
                              roll * kDegrees, pitch * kDegrees, yaw * kDegrees};
    for (size_t k = 0; k < 6; ++k) pose_[k]->setValue(values[k]);
  }
}

void WorldTab::applyPose() {
  const std::string model = chosenModel();
  if (model.empty()) {
    report_("choose a model in the tree");
    return;
  }
  geometry_msgs::Pose pose;
  pose.position.x = pose_[0]->value();
  pose.position.y = pose_[1]->value();
  pose.position.z = pose_[2]->value();
  tf2::Quaternion q;
  q.setRPY(pose_[3]->value() / kDegrees, pose_[4]->value() / kDegrees,
           pose_[5]->value() / kDegrees);
  pose.orientation.x = q.x();
  pose.orientation.y = q.y();
  pose.orientation.z = q.z();
  pose.orientation.w = q.w();
  client_->setModelPose(model, pose, reportOnGui(this, report_));
}

void WorldTab::showPhysics(const PhysicsState& state) {
  physics_ = state;
  physics_known_ = true;
  const QDoubleSpinBox* boxes[5] = {step_size_, factor_target_, gravity_[0], gravity_[1],
                                    gravity_[2]};
  if (anyHasFocus(boxes, 5)) return;  // the user is typing physics
  step_size_->setValue(state.time_step);
  factor_target_->setValue(state.max_update_rate * state.time_step);
  gravity_[0]->setValue(state.gravity.x);
  gravity_[1]->setValue(state.gravity.y);
  gravity_[2]->setValue(state.gravity.z);
}

void WorldTab::applyPhysics() {
  if (!physics_known_) {
    report_("the physics are not known yet: is the simulator running?");
    return;
  }
  PhysicsState state = physics_;
  state.time_step = step_size_->value();
  state.max_update_rate = factor_target_->value() / state.time_step;
  state.gravity.x = gravity_[0]->value();
  state.gravity.y = gravity_[1]->value();
  state.gravity.z = gravity_[2]->value();
  client_->setPhysics(state, reportOnGui(this, report_, [this](const Outcome&) {
                        physics_changed_();
                      }));
}

}  // namespace gazebo_ros_panels
