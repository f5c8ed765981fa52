// Gazebo's selection in the simulator's rviz view (gazebo_ros_panels/SelectModel): a left click
// on a model's visuals (the ModelVisuals display's) selects that model, its name on the latched
// kSelectedModelTopic; a click on nothing or on the ground plane, which Gazebo never selects,
// clears the selection (an empty name). The selection is the process's one (Selection::hub(),
// which the World tab's tree shares); this tool publishes it whenever it changes. The model
// handles (gazebo_ros.model_handles) put their arrows and rings on the selected model alone, as
// Gazebo's translate and rotate modes do, and this tool drags them: a press on a handle's control,
// or a press that moves before its release, is rviz's Interact tool's (the control dragged, or
// the camera moved).
#pragma once

#include <ros/node_handle.h>
#include <ros/publisher.h>
#include <rviz/default_plugin/tools/interaction_tool.h>

#include <string>

namespace gazebo_ros_panels {

const char* const kSelectedModelTopic = "/gazebo_window/selected_model";
// rviz's ModelVisuals namespace of Gazebo's ground plane, which is never selected.
const char* const kGroundPlane = "ground_plane";

class SelectModelTool : public rviz::InteractionTool {
  Q_OBJECT
 public:
  SelectModelTool();
  void onInitialize() override;
  int processMouseEvent(rviz::ViewportMouseEvent& event) override;

 private:
  std::string modelAt(rviz::ViewportMouseEvent& event);  // "" where no model is drawn
  void publish(const QString& model);  // on kSelectedModelTopic, with the tool's status

  ros::NodeHandle node_;
  ros::Publisher selected_;
  bool pressed_on_control_ = false;
  int press_x_ = 0, press_y_ = 0;
};

}  // namespace gazebo_ros_panels
