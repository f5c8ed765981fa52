// Gazebo's Edit and View menus in rviz's menu bar, before its Help.
// Edit > Reset Model Poses (Ctrl+Shift+R): every model back at its spawn pose, through the
// simulator's reset_world (gazebo_ros' reset_world is what Gazebo's Reset Model Poses does: the
// models reset, not the time).
// View: the whole world transparent or wireframe (the model visuals display's properties,
// ModelVisuals), and the collisions, joints, centres of mass, inertias and contacts shown or not
// (world.rviz's displays of those names), each a checkable entry that toggles without a restart
// and shows the current state when the menu opens. An entry whose display the view does not have
// is greyed out.
#pragma once

#include <QMenu>
#include <QObject>
#include <QPointer>
#include <QString>

#include <functional>

namespace rviz {
class Display;
class VisualizationManager;
}  // namespace rviz

namespace gazebo_ros_panels {

class GazeboClient;

class GazeboMenus : public QObject {
 public:
  GazeboMenus(rviz::VisualizationManager* manager, GazeboClient* client,
              std::function<void(const QString&)> report, QObject* parent);
  ~GazeboMenus() override;  // the menus leave rviz's menu bar with the panel

 private:
  void addEditMenu(GazeboClient* client);
  void addViewMenu();
  void showViewStates();
  rviz::Display* display(const QString& name) const;

  rviz::VisualizationManager* manager_;
  std::function<void(const QString&)> report_;
  QPointer<QMenu> edit_, view_;
};

}  // namespace gazebo_ros_panels
