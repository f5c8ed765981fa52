#include "view_focus.h"

#include <OgreQuaternion.h>
#include <OgreVector3.h>
#include <geometry_msgs/Pose.h>
#include <rviz/display_context.h>
#include <rviz/frame_manager.h>
#include <rviz/properties/tf_frame_property.h>
#include <rviz/properties/vector_property.h>
#include <rviz/view_controller.h>
#include <rviz/view_manager.h>

#include "gazebo_client.h"
#include "gui_thread.h"

namespace gazebo_ros_panels {
namespace {

// The frame of the simulator's poses (gazebo_msgs' "world").
const char* const kWorldFrame = "world";
// Milliseconds between two moves of a following view: the view's 20 frames a second.
const int kFollowPeriodMs = 50;
// Model states older than this (steady ns) are the paused world's last: the pose is asked for.
const int64_t kStaleStatesNs = 500000000;

}  // namespace

ViewFocus::ViewFocus(rviz::DisplayContext* context, GazeboClient* client,
                     std::function<void(const QString&)> report, QObject* parent)
    : QObject(parent), context_(context), client_(client), report_(std::move(report)) {
  connect(&follow_timer_, &QTimer::timeout, this, &ViewFocus::track);
}

void ViewFocus::moveTo(const std::string& model) {
  follow("");
  ask(model, false);
}

void ViewFocus::follow(const std::string& model) {
  if (model.empty()) {
    if (following_.empty()) return;
    report_(QString("not following %1").arg(QString::fromStdString(following_)));
    following_.clear();
    follow_timer_.stop();
    return;
  }
  following_ = model;
  report_(QString("following %1 (its menu's Stop Following stops)")
              .arg(QString::fromStdString(model)));
  follow_timer_.start(kFollowPeriodMs);
  track();
}

void ViewFocus::track() {
  if (following_.empty()) return;
  geometry_msgs::Pose pose;
  QString why;
  if (client_->recentModelPose(following_, kStaleStatesNs, &pose)) {
    if (!focusOn(pose.position, &why)) {
      report_(why);
      follow("");
    }
    return;
  }
  if (!asking_) ask(following_, true);
}

void ViewFocus::ask(const std::string& model, bool following) {
  if (following) asking_ = true;
  client_->modelPose(model, [this, model, following](const Outcome& outcome,
                                                     const geometry_msgs::Pose& pose) {
    onGuiThread(this, [this, model, following, outcome, pose] {
      if (following) asking_ = false;
      if (following && model != following_) return;  // followed no longer
      QString why = QString::fromStdString(outcome.text);
      if (outcome.ok && focusOn(pose.position, &why)) {
        if (!following) report_(QString("view moved to %1").arg(QString::fromStdString(model)));
        return;
      }
      report_(why);
      if (following) follow("");
    });
  });
}

bool ViewFocus::focusOn(const geometry_msgs::Point& point, QString* why) {
  rviz::ViewController* view = context_->getViewManager()->getCurrent();
  auto* focal =
      view ? dynamic_cast<rviz::VectorProperty*>(view->subProp("Focal Point")) : nullptr;
  if (!focal) {
    *why = QString("the current view (%1) has no focal point to move")
               .arg(view ? view->getClassId() : QString("none"));
    return false;
  }
  // The focal point is relative to the view's target frame's origin, in the fixed frame.
  rviz::FrameManager* frames = context_->getFrameManager();
  geometry_msgs::Pose pose;
  pose.position = point;
  pose.orientation.w = 1;
  Ogre::Vector3 in_fixed, target = Ogre::Vector3::ZERO;
  Ogre::Quaternion orientation;
  if (!frames->transform(kWorldFrame, ros::Time(), pose, in_fixed, orientation)) {
    *why = QString("no transform from %1 to the fixed frame %2")
               .arg(kWorldFrame, QString::fromStdString(frames->getFixedFrame()));
    return false;
  }
  const QString target_frame = view->subProp("Target Frame")->getValue().toString();
  if (!target_frame.isEmpty() && target_frame != rviz::TfFrameProperty::FIXED_FRAME_STRING &&
      !frames->getTransform(target_frame.toStdString(), ros::Time(), target, orientation)) {
    *why = QString("no transform from the view's target frame %1 to the fixed frame")
               .arg(target_frame);
    return false;
  }
  focal->setVector(in_fixed - target);
  return true;
}

}  // namespace gazebo_ros_panels
