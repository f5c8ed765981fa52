// Gazebo's Move To and Follow in rviz's 3D view: the current view controller's focal point put on
// a model of the simulator (its origin, in the world frame), the view's distance, yaw and pitch
// kept, so that the camera comes along to look at the model as it looked at the point before.
// Following, the focal point goes with the model on each tick, from the model states the panel
// receives, or while none come (a paused world publishes none) from get_model_state, until
// another model is followed, following is stopped, or the model is gone. A view without a focal
// point (rviz's FPS view), or a model the simulator does not have, is reported, and the view
// stays.
#pragma once

#include <QObject>
#include <QString>
#include <QTimer>
#include <geometry_msgs/Point.h>

#include <functional>
#include <string>

namespace rviz {
class DisplayContext;
}

namespace gazebo_ros_panels {

class GazeboClient;

class ViewFocus : public QObject {
 public:
  ViewFocus(rviz::DisplayContext* context, GazeboClient* client,
            std::function<void(const QString&)> report, QObject* parent);
  void moveTo(const std::string& model);  // stops following
  void follow(const std::string& model);  // an empty name stops following

 private:
  void track();  // the followed model's latest pose, to the focal point
  // Asks the simulator for model's pose; then, when `following` is the followed model (still) or
  // empty (a Move To), puts the focal point there.
  void ask(const std::string& model, bool following);
  bool focusOn(const geometry_msgs::Point& point, QString* why);  // false: the view stays

  rviz::DisplayContext* context_;
  GazeboClient* client_;
  std::function<void(const QString&)> report_;
  QTimer follow_timer_;
  std::string following_;  // empty: following none
  bool asking_ = false;    // a follow's get_model_state under way
};

}  // namespace gazebo_ros_panels
