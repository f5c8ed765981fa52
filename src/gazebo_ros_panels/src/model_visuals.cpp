#include "model_visuals.h"

#include <OGRE/OgreMaterialManager.h>
#include <OGRE/OgrePass.h>
#include <OGRE/OgreTechnique.h>
#include <pluginlib/class_list_macros.hpp>
#include <rviz/default_plugin/marker_utils.h>
#include <rviz/default_plugin/markers/marker_selection_handler.h>
#include <rviz/display_context.h>
#include <rviz/properties/bool_property.h>
#include <rviz/properties/int_property.h>
#include <rviz/properties/ros_topic_property.h>

#include <sstream>

namespace gazebo_ros_panels {
namespace {

// Gazebo's transparency of a model made transparent (its View > Transparent).
constexpr float kTransparency = 0.5f;
// rviz/Marker's DELETEALL (visualization_msgs' constant is newer than some of its users).
constexpr int kDeleteAll = 3;

// rviz's marker keeps its selection handler, which picking finds, protected: read through a
// member pointer named in a derived type, which C++ allows.
struct MarkerHandler : rviz::MarkerBase {
  static const rviz::SelectionHandler* of(const rviz::MarkerBase& marker) {
    return (marker.*(&MarkerHandler::handler_)).get();
  }
};

}  // namespace

std::set<std::string> modelNames(const std::string& lines) {
  std::set<std::string> names;
  std::istringstream in(lines);
  for (std::string name; std::getline(in, name);)
    if (!name.empty()) names.insert(name);
  return names;
}

ModelVisuals::ModelVisuals() {
  transparent_property_ = new rviz::BoolProperty(
      "Transparent", false,
      "Every model at half its alpha (Gazebo's View > Transparent); one model alone from its "
      "right-click menu's View",
      this, SLOT(applyModesToAll()));
  wireframe_property_ = new rviz::BoolProperty(
      "Wireframe", false,
      "Every model's triangles' edges only (Gazebo's View > Wireframe); one model alone from its "
      "right-click menu's View",
      this, SLOT(applyModesToAll()));
  models_property_ = new rviz::Property("Models", QVariant(), "Each model's visuals, shown or not",
                                        this);
}

ModelVisuals::~ModelVisuals() {
  unsubscribe();
  clearShown();
}

void ModelVisuals::subscribe() {
  if (!isEnabled()) return;
  const std::string topic = marker_topic_property_->getTopicStd();
  if (topic.empty()) return;
  try {
    markers_sub_ = update_nh_.subscribe(topic, queue_size_property_->getInt(),
                                        &ModelVisuals::incomingArray, this);
    auto into = [this](std::set<std::string>* models) {
      return [this, models](const std_msgs::String::ConstPtr& names) { setModels(models, names); };
    };
    transparent_sub_ = update_nh_.subscribe<std_msgs::String>(kTransparentModelsTopic, 1,
                                                              into(&transparent_models_));
    wireframe_sub_ = update_nh_.subscribe<std_msgs::String>(kWireframeModelsTopic, 1,
                                                            into(&wireframe_models_));
    setStatus(rviz::StatusProperty::Ok, "Topic", "OK");
  } catch (const ros::Exception& error) {
    setStatus(rviz::StatusProperty::Error, "Topic",
              QString("Error subscribing: ") + error.what());
  }
}

void ModelVisuals::unsubscribe() {
  markers_sub_.shutdown();
  transparent_sub_.shutdown();
  wireframe_sub_.shutdown();
}

void ModelVisuals::onDisable() {
  MarkerArrayDisplay::onDisable();
  clearShown();
}

void ModelVisuals::reset() {
  MarkerArrayDisplay::reset();
  clearShown();
}

void ModelVisuals::fixedFrameChanged() {
  MarkerArrayDisplay::fixedFrameChanged();
  clearShown();
}

std::string ModelVisuals::modelOf(const rviz::SelectionHandler* handler) const {
  for (const auto& [id, shown] : shown_)
    if (handler && MarkerHandler::of(*shown.marker) == handler) return id.first;
  return "";
}

void ModelVisuals::clearShown() {
  shown_.clear();
  if (context_) context_->queueRender();
}

// On rviz's GUI thread: update_nh_'s callbacks run there.
void ModelVisuals::incomingArray(const visualization_msgs::MarkerArray::ConstPtr& array) {
  if (!rviz::checkMarkerArrayMsg(*array, this)) return;
  for (const visualization_msgs::Marker& message : array->markers) show(message);
  context_->queueRender();
}

void ModelVisuals::show(const visualization_msgs::Marker& message) {
  const rviz::MarkerID id(message.ns, message.id);
  if (message.action == visualization_msgs::Marker::DELETE) {
    shown_.erase(id);
    return;
  }
  if (message.action == kDeleteAll) {
    shown_.clear();
    return;
  }
  if (message.action != visualization_msgs::Marker::ADD || !rviz::checkMarkerMsg(message, this))
    return;
  auto model = model_shown_.find(message.ns);
  if (model == model_shown_.end()) {
    model = model_shown_.emplace(message.ns, new rviz::BoolProperty(
        QString::fromStdString(message.ns), true, "This model's visuals shown",
        models_property_, SLOT(showChosenModels()), this)).first;
  }
  if (!model->second->getBool()) return;
  auto it = shown_.find(id);
  if (it != shown_.end() && it->second.marker->getMessage()->type != message.type) {
    shown_.erase(it);
    it = shown_.end();
  }
  if (it == shown_.end()) {
    rviz::MarkerBasePtr marker(rviz::createMarker(message.type, this, context_, scene_node_));
    if (!marker) return;  // a type rviz does not draw; checkMarkerMsg said so
    it = shown_.emplace(id, Shown{marker, {}}).first;
  }
  // rviz's marker sets its materials' colour and blending from a message (from every message,
  // or from one whose colour changed): the modes go on after it.
  it->second.marker->setMessage(message);
  applyModes(message.ns, &it->second);
}

void ModelVisuals::applyModes(const std::string& model, Shown* shown) {
  const bool transparent = transparent_property_->getBool() || transparent_models_.count(model);
  const bool wireframe = wireframe_property_->getBool() || wireframe_models_.count(model);
  std::map<Ogre::Pass*, PassLook> looks;
  for (const Ogre::MaterialPtr& material : shown->marker->getMaterials()) {
    for (Ogre::Technique* technique : material->getTechniques()) {
      // rviz's selection draws its own schemes (Pick, Depth): a model is picked whole.
      if (technique->getSchemeName() != Ogre::MaterialManager::DEFAULT_SCHEME_NAME) continue;
      for (Ogre::Pass* pass : technique->getPasses()) {
        pass->setPolygonMode(wireframe ? Ogre::PM_WIREFRAME : Ogre::PM_SOLID);
        auto look = shown->looks.find(pass);
        // A pass whose alpha is not the one made transparent here: rviz set its look since.
        const bool made_transparent =
            look != shown->looks.end() && pass->getDiffuse().a == look->second.transparent_alpha;
        if (transparent && !made_transparent) {
          PassLook own{pass->getDiffuse(), pass->getSourceBlendFactor(),
                       pass->getDestBlendFactor(), 0.0f};
          Ogre::ColourValue diffuse = own.diffuse;
          diffuse.a *= kTransparency;
          own.transparent_alpha = diffuse.a;
          pass->setDiffuse(diffuse);
          // Blended, still writing depth: OGRE draws transparent objects from the farthest (by
          // their centres) to the nearest, and the ground plane's centre is nearer the camera
          // than a model standing beyond it; drawn after that model, the plane must not cover it.
          pass->setSceneBlending(Ogre::SBT_TRANSPARENT_ALPHA);
          looks[pass] = own;
        } else if (transparent) {
          looks[pass] = look->second;
        } else if (made_transparent) {
          pass->setDiffuse(look->second.diffuse);
          pass->setSceneBlending(look->second.source, look->second.destination);
        }
      }
    }
  }
  shown->looks = std::move(looks);  // of the passes the marker has now
}

void ModelVisuals::showChosenModels() {
  for (auto it = shown_.begin(); it != shown_.end();) {
    auto model = model_shown_.find(it->first.first);
    if (model != model_shown_.end() && !model->second->getBool())
      it = shown_.erase(it);
    else
      ++it;
  }
  if (context_) context_->queueRender();
}

void ModelVisuals::applyModesToAll() {
  for (auto& [id, shown] : shown_) applyModes(id.first, &shown);
  if (context_) context_->queueRender();
}

void ModelVisuals::setModels(std::set<std::string>* models,
                             const std_msgs::String::ConstPtr& names) {
  *models = modelNames(names->data);
  applyModesToAll();
}

}  // namespace gazebo_ros_panels

PLUGINLIB_EXPORT_CLASS(gazebo_ros_panels::ModelVisuals, rviz::Display)
