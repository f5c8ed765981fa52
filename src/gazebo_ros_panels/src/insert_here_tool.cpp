#include "insert_here_tool.h"

#include <OgrePlane.h>
#include <OgreVector3.h>
#include <pluginlib/class_list_macros.hpp>
#include <rviz/display_context.h>
#include <rviz/geometry.h>
#include <rviz/load_resource.h>
#include <rviz/selection/selection_manager.h>
#include <rviz/viewport_mouse_event.h>

#include "placement.h"

namespace gazebo_ros_panels {

InsertHereTool::InsertHereTool() { shortcut_key_ = 'n'; }

void InsertHereTool::onInitialize() {
  setName("Insert Here");
  setIcon(rviz::loadPixmap("package://rviz/icons/classes/PublishPoint.png"));
}

int InsertHereTool::processMouseEvent(rviz::ViewportMouseEvent& event) {
  if (!event.leftDown()) return Render;
  Ogre::Vector3 point;
  Ogre::Plane ground(Ogre::Vector3::UNIT_Z, 0.0);
  const bool on_something =
      context_->getSelectionManager()->get3DPoint(event.viewport, event.x, event.y, point);
  if (!on_something &&
      !rviz::getPointOnPlaneFromWindowXY(event.viewport, ground, event.x, event.y, point)) {
    setStatus("nothing under the cursor, and the ground plane is not in view there");
    return Render;
  }
  Q_EMIT Placement::hub().chosen(point.x, point.y, point.z);
  return Render | Finished;
}

}  // namespace gazebo_ros_panels

PLUGINLIB_EXPORT_CLASS(gazebo_ros_panels::InsertHereTool, rviz::Tool)
