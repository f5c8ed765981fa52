#include "select_model_tool.h"

#include <pluginlib/class_list_macros.hpp>
#include <rviz/display_context.h>
#include <rviz/display_group.h>
#include <rviz/load_resource.h>
#include <rviz/selection/selection_manager.h>
#include <rviz/viewport_mouse_event.h>
#include <std_msgs/String.h>

#include <cstdlib>

#include "model_visuals.h"
#include "selection.h"

namespace gazebo_ros_panels {
namespace {

// A press and release this many pixels apart or closer is a click; further, a drag.
constexpr int kClickSlack = 3;

// The model of the ModelVisuals displays in `group` (and its subgroups) that `handler` picked.
std::string pickedModel(rviz::DisplayGroup* group, const rviz::SelectionHandler* handler) {
  for (int i = 0; i < group->numDisplays(); ++i) {
    rviz::Display* display = group->getDisplayAt(i);
    std::string model;
    if (auto* visuals = dynamic_cast<ModelVisuals*>(display))
      model = visuals->modelOf(handler);
    else if (auto* subgroup = dynamic_cast<rviz::DisplayGroup*>(display))
      model = pickedModel(subgroup, handler);
    if (!model.empty()) return model;
  }
  return "";
}

}  // namespace

SelectModelTool::SelectModelTool() = default;

void SelectModelTool::onInitialize() {
  InteractionTool::onInitialize();
  setName("Select Model");
  setIcon(rviz::loadPixmap("package://rviz/icons/classes/Interact.png"));
  // Nothing is published until a selection: the model handles start with none selected.
  selected_ = node_.advertise<std_msgs::String>(kSelectedModelTopic, 1, true);
  Selection& selection = Selection::hub();
  connect(&selection, &Selection::changed, this, &SelectModelTool::publish);
  if (!selection.model().isEmpty()) publish(selection.model());
}

int SelectModelTool::processMouseEvent(rviz::ViewportMouseEvent& event) {
  const int flags = InteractionTool::processMouseEvent(event);
  if (event.leftDown()) {
    // The base tool has taken the press: on a control it has the focus.
    rviz::InteractiveObjectPtr focused = focused_object_.lock();
    pressed_on_control_ = focused && focused->isInteractive();
    press_x_ = event.x;
    press_y_ = event.y;
  } else if (event.leftUp() && !pressed_on_control_ &&
             std::abs(event.x - press_x_) + std::abs(event.y - press_y_) <= kClickSlack) {
    const QString model = QString::fromStdString(modelAt(event));
    if (model == Selection::hub().model())
      publish(model);  // said again: the click is answered
    else
      Selection::hub().select(model);
  }
  return flags;
}

std::string SelectModelTool::modelAt(rviz::ViewportMouseEvent& event) {
  rviz::SelectionManager* selection = context_->getSelectionManager();
  rviz::M_Picked picked;
  selection->pick(event.viewport, event.x, event.y, event.x + 1, event.y + 1, picked, true);
  for (const auto& [handle, _] : picked) {
    const std::string model = pickedModel(context_->getRootDisplayGroup(),
                                          selection->getHandler(handle));
    if (!model.empty() && model != kGroundPlane) return model;
  }
  return "";
}

void SelectModelTool::publish(const QString& model) {
  std_msgs::String name;
  name.data = model.toStdString();
  selected_.publish(name);
  setStatus(model.isEmpty() ? QString("no model selected: click one to move it")
                            : QString("selected %1").arg(model));
}

}  // namespace gazebo_ros_panels

PLUGINLIB_EXPORT_CLASS(gazebo_ros_panels::SelectModelTool, rviz::Tool)
