// rviz's "Insert Here" tool (gazebo_ros_panels/InsertHere): a left click in the 3D view puts the
// Insert tab's chosen model at the point under the cursor (on what is drawn there, else on the
// ground plane z = 0), then rviz goes back to its default tool.
#pragma once

#include <rviz/tool.h>

namespace gazebo_ros_panels {

class InsertHereTool : public rviz::Tool {
  Q_OBJECT
 public:
  InsertHereTool();
  void onInitialize() override;
  void activate() override {}
  void deactivate() override {}
  int processMouseEvent(rviz::ViewportMouseEvent& event) override;
};

}  // namespace gazebo_ros_panels
