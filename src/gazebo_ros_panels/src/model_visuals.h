// The models' visuals as Gazebo's window draws them, with Gazebo's view modes: an rviz display of
// a MarkerArray topic (the simulator's /gazebo/visual_markers, one namespace per model) that draws
// each marker as rviz's Marker display does and makes a model transparent (its visuals at half
// their alpha, Gazebo's transparency of 0.5) or wireframe (their triangles' edges) without a
// restart. The whole world: the display's "Transparent" and "Wireframe" properties (the Gazebo
// panel's View menu sets them). One model: its name on the latched kTransparentModelsTopic or
// kWireframeModelsTopic (std_msgs/String, the names one a line: the model handles' right-click
// View menu publishes them). The modes change the markers' own materials (their default scheme:
// rviz's picking still sees a model whole), after each marker message rviz's marker applies.
// Markers are added, changed and deleted (ADD, DELETE, DELETEALL) as rviz's display does; a
// marker's lifetime and frame locking, which the simulator's markers do not use, are not
// followed. Each model has a checkbox under "Models" (shown or not), as the Marker display has
// one per namespace.
#pragma once

// marker_base.h holds Ogre::MaterialPtr in a set: the type complete first.
#include <OGRE/OgreMaterial.h>
#include <rviz/default_plugin/marker_array_display.h>
#include <rviz/default_plugin/markers/marker_base.h>
#include <std_msgs/String.h>
#include <visualization_msgs/MarkerArray.h>

#include <OGRE/OgreColourValue.h>
#include <OGRE/OgreCommon.h>
#include <OGRE/OgreBlendMode.h>

#include <map>
#include <set>
#include <string>

namespace Ogre {
class Pass;
}

namespace rviz {
class BoolProperty;
class Property;
class SelectionHandler;
}

namespace gazebo_ros_panels {

const char* const kTransparentModelsTopic = "/gazebo_window/transparent_models";
const char* const kWireframeModelsTopic = "/gazebo_window/wireframe_models";

// The names of a kTransparentModelsTopic or kWireframeModelsTopic message.
std::set<std::string> modelNames(const std::string& lines);

class ModelVisuals : public rviz::MarkerArrayDisplay {
  Q_OBJECT
 public:
  ModelVisuals();
  ~ModelVisuals() override;
  void reset() override;
  void fixedFrameChanged() override;
  // The model (a marker's namespace) whose drawn marker rviz's picking found through `handler`,
  // "" if none of this display's.
  std::string modelOf(const rviz::SelectionHandler* handler) const;

 protected:
  void subscribe() override;
  void unsubscribe() override;
  void onDisable() override;

 private Q_SLOTS:
  void applyModesToAll();
  void showChosenModels();  // the markers of the models unticked under "Models" taken away

 private:
  // What a pass made transparent had before, to put back, and the alpha it was given.
  struct PassLook {
    Ogre::ColourValue diffuse;
    Ogre::SceneBlendFactor source, destination;
    float transparent_alpha;
  };
  struct Shown {
    rviz::MarkerBasePtr marker;
    std::map<Ogre::Pass*, PassLook> looks;  // the passes made transparent
  };

  void incomingArray(const visualization_msgs::MarkerArray::ConstPtr& array);
  void show(const visualization_msgs::Marker& message);
  void applyModes(const std::string& model, Shown* shown);
  void setModels(std::set<std::string>* models, const std_msgs::String::ConstPtr& names);
  void clearShown();

  rviz::BoolProperty* transparent_property_;
  rviz::BoolProperty* wireframe_property_;
  rviz::Property* models_property_;
  // Under models_property_, one per model seen, kept (as rviz's namespaces are) while the display
  // lives.
  std::map<std::string, rviz::BoolProperty*> model_shown_;
  ros::Subscriber markers_sub_, transparent_sub_, wireframe_sub_;
  std::map<rviz::MarkerID, Shown> shown_;
  std::set<std::string> transparent_models_, wireframe_models_;
};

}  // namespace gazebo_ros_panels
