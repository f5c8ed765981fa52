// The Gazebo panel of rviz: Gazebo's Time bar, Insert tab and World tab over the simulator's
// gazebo_ros services (GazeboClient), Gazebo's translate/rotate mode as a button that toggles it,
// a line saying what the last action did or why not, the view's Move To and Follow asked for by
// the model handles' right-click menu (ViewFocus), and Gazebo's Edit and View menus in rviz's menu
// bar (GazeboMenus).
#pragma once

#include <QLabel>
#include <QTimer>
#include <rviz/panel.h>

#include <memory>

namespace rviz {
class Display;
}

namespace gazebo_ros_panels {

class GazeboClient;
class TimeTab;
class InsertTab;
class WorldTab;
class ViewFocus;

class GazeboPanel : public rviz::Panel {
  Q_OBJECT
 public:
  explicit GazeboPanel(QWidget* parent = nullptr);
  ~GazeboPanel() override;
  void onInitialize() override;

 private:
  void report(const QString& text);
  // The clock's figures, the model states and the view's frames per second, several times a
  // second.
  void refresh();
  // The frames the view drew over its last whole second (OGRE's statistics of rviz's render
  // window), shown (whole frames) and published (GazeboClient::publishFrameRate) once a wall
  // second.
  void showFrameRate(int64_t now_wall_ns);
  void askForPhysics();   // the pause state and the physics, unless a call is under way
  void useTool(const QString& class_id);  // the rviz tool made current (added if not there)
  void chooseInsertPoint();  // rviz's Insert Here tool made current
  // Gazebo's translate and rotate modes, on and off: the model handles' display shown (added if
  // the view has none) and the Select Model tool made current, or the handles hidden.
  void toggleMoveModels();
  rviz::Display* handlesDisplay(bool add);  // the model handles' display, nullptr if none
  // Tabbed with rviz's Displays panel in its dock, raised (as Gazebo's World and Insert tabs
  // share its left panel): the sensors' image panels docked below keep their room. A saved
  // window state (rviz's config) places it as saved.
  void shareTheDisplaysPlace();

  std::unique_ptr<GazeboClient> client_;
  TimeTab* time_ = nullptr;
  InsertTab* insert_ = nullptr;
  WorldTab* world_ = nullptr;
  ViewFocus* view_focus_ = nullptr;
  QLabel* status_ = nullptr;
  QTimer refresh_timer_;
  QTimer physics_timer_;
  bool physics_pending_ = false;
  int64_t frame_rate_published_ns_ = 0;  // steady wall time
  QString last_physics_error_;
};

}  // namespace gazebo_ros_panels
