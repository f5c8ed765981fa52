#include "model_plugins.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <utility>

#include <onedof_sim/text_number.h>
#include <onedof_sim/trim.h>
#include <ros/console.h>
#include <ros/exceptions.h>
#include <ros/node_handle.h>
#include <tinyxml2.h>

#include "plugin_params.h"
#include "sensors/sensor_xml.h"

namespace onedof_sim::plugins {
namespace {

std::string attribute(const tinyxml2::XMLElement* element, const char* name) {
  const char* value = element->Attribute(name);
  return value ? value : "";
}

std::string childText(const tinyxml2::XMLElement* element, const char* name) {
  const tinyxml2::XMLElement* child = element->FirstChildElement(name);
  const char* text = child ? child->GetText() : nullptr;
  return text ? text : "";
}

PluginElement toPluginElement(const tinyxml2::XMLElement* plugin) {
  tinyxml2::XMLPrinter printer;
  plugin->Accept(&printer);
  PluginElement element;
  element.name = attribute(plugin, "name");
  element.filename = attribute(plugin, "filename");
  element.xml = printer.CStr();
  element.robot_namespace = childText(plugin, "robotNamespace");
  return element;
}

// Gazebo's rule: every element whose name starts with "plugin", at any depth.
void addRobotNamespace(tinyxml2::XMLElement* element, const std::string& robot_namespace) {
  for (auto* child = element->FirstChildElement(); child; child = child->NextSiblingElement()) {
    if (std::string(child->Name()).rfind("plugin", 0) == 0 &&
        !child->FirstChildElement("robotNamespace")) {
      tinyxml2::XMLElement* added = child->InsertNewChildElement("robotNamespace");
      added->SetText(robot_namespace.c_str());
    }
    addRobotNamespace(child, robot_namespace);
  }
}

void addPlugins(const tinyxml2::XMLElement* parent, std::vector<PluginElement>* out) {
  for (auto* plugin = parent->FirstChildElement("plugin"); plugin;
       plugin = plugin->NextSiblingElement("plugin"))
    out->push_back(toPluginElement(plugin));
}

// A <sensor> element and what it says, or why it is malformed (SensorElement::error).
SensorElement toSensorElement(const tinyxml2::XMLElement* sensor, const std::string& link) {
  SensorElement element;
  element.name = attribute(sensor, "name");
  element.type = attribute(sensor, "type");
  element.link = link;
  tinyxml2::XMLPrinter printer;
  sensor->Accept(&printer);
  element.xml = printer.CStr();
  addPlugins(sensor, &element.plugins);
  auto fail = [&](const std::string& why) {
    if (element.error.empty()) element.error = why;
  };
  if (element.name.empty()) fail("it has no name");
  if (element.type.empty()) fail("it has no type");
  if (link.empty()) fail("it is on no link (a <gazebo> without reference)");
  if (sensor->FirstChildElement("pose")) {
    const std::string text = trimmed(childText(sensor, "pose"));
    if (!readPoseText(text, &element.pose)) fail("<pose> is '" + text + "', not six numbers");
  }
  if (sensor->FirstChildElement("update_rate")) {
    const std::string text = trimmed(childText(sensor, "update_rate"));
    if (!numberIn(text, &element.update_rate) || !std::isfinite(element.update_rate) ||
        element.update_rate < 0)
      fail("<update_rate> is '" + text + "', not a number of Hz >= 0");
  }
  for (const auto& [tag, value] : {std::pair{"always_on", &element.always_on},
                                   std::pair{"visualize", &element.visualize}})
    if (sensor->FirstChildElement(tag) && !readFlag(trimmed(childText(sensor, tag)), value))
      fail("<" + std::string(tag) + "> is '" + trimmed(childText(sensor, tag)) +
           "', not true or false");
  return element;
}

}  // namespace

std::string withRobotNamespace(const std::string& model_xml, const std::string& robot_namespace) {
  if (robot_namespace.empty()) return model_xml;
  tinyxml2::XMLDocument doc;
  if (doc.Parse(model_xml.c_str(), model_xml.size()) != tinyxml2::XML_SUCCESS) return model_xml;
  tinyxml2::XMLElement* root = doc.RootElement();
  if (!root) return model_xml;
  addRobotNamespace(root, robot_namespace);
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  return printer.CStr();
}

std::vector<PluginElement> findModelPlugins(const std::string& model_xml, ModelFormat format) {
  std::vector<PluginElement> found;
  tinyxml2::XMLDocument doc;
  if (doc.Parse(model_xml.c_str(), model_xml.size()) != tinyxml2::XML_SUCCESS) return found;
  if (format == ModelFormat::Urdf) {
    const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
    if (!robot) return found;
    for (auto* gazebo = robot->FirstChildElement("gazebo"); gazebo;
         gazebo = gazebo->NextSiblingElement("gazebo"))
      addPlugins(gazebo, &found);
    return found;
  }
  const tinyxml2::XMLElement* sdf = doc.FirstChildElement("sdf");
  const tinyxml2::XMLElement* model = sdf ? sdf->FirstChildElement("model") : nullptr;
  if (model) addPlugins(model, &found);
  return found;
}

std::vector<SensorElement> findSensors(const std::string& model_xml, ModelFormat format) {
  std::vector<SensorElement> found;
  tinyxml2::XMLDocument doc;
  if (doc.Parse(model_xml.c_str(), model_xml.size()) != tinyxml2::XML_SUCCESS) return found;
  auto add = [&](const tinyxml2::XMLElement* parent, const std::string& link) {
    for (auto* sensor = parent->FirstChildElement("sensor"); sensor;
         sensor = sensor->NextSiblingElement("sensor"))
      found.push_back(toSensorElement(sensor, link));
  };
  if (format == ModelFormat::Urdf) {
    const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
    if (!robot) return found;
    for (auto* gazebo = robot->FirstChildElement("gazebo"); gazebo;
         gazebo = gazebo->NextSiblingElement("gazebo"))
      add(gazebo, attribute(gazebo, "reference"));
    return found;
  }
  const tinyxml2::XMLElement* sdf = doc.FirstChildElement("sdf");
  const tinyxml2::XMLElement* model = sdf ? sdf->FirstChildElement("model") : nullptr;
  if (!model) return found;
  for (auto* link = model->FirstChildElement("link"); link; link = link->NextSiblingElement("link"))
    add(link, attribute(link, "name"));
  return found;
}

namespace {

bool endsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Whether a <plugin> parameter's tag names a topic or a service (see invalidPluginName).
bool namesTopicOrService(const std::string& tag) {
  for (const char* suffix : {"Topic", "TopicName", "topicName", "ServiceName", "serviceName"})
    if (endsWith(tag, suffix)) return true;
  return false;
}

// roscpp's refusal of `name` (a topic or service; empty: the namespace itself) in namespace `ns`
// (empty: the root), as a plugin's node handle and advertise or subscribe meet it; empty if
// roscpp takes it.
std::string rosNameRefusal(const std::string& ns, const std::string& name) {
  try {
    ros::NodeHandle node(ns.empty() ? "/" : ns);
    if (!name.empty()) node.resolveName(name);
  } catch (const ros::InvalidNameException& e) {
    return e.what();
  }
  return "";
}

std::string invalidNameIn(const PluginElement& element, const std::string& where) {
  auto refused = [&](const std::string& tag, const std::string& value, const std::string& why) {
    return "plugin '" + element.name + "' (" + element.filename + where + "): <" + tag + "> '" +
           value + "' is not a valid ROS name: " + why;
  };
  std::string why = rosNameRefusal(element.robot_namespace, "");
  if (!why.empty()) return refused("robotNamespace", element.robot_namespace, why);
  tinyxml2::XMLDocument doc;
  if (doc.Parse(element.xml.c_str(), element.xml.size()) != tinyxml2::XML_SUCCESS) return "";
  const tinyxml2::XMLElement* plugin = doc.RootElement();
  for (auto* child = plugin ? plugin->FirstChildElement() : nullptr; child;
       child = child->NextSiblingElement()) {
    const std::string tag = child->Name();
    const std::string value = trimmed(child->GetText());
    if (tag == "cameraName") why = rosNameRefusal(element.robot_namespace + "/" + value, "");
    else if (namesTopicOrService(tag)) why = rosNameRefusal(element.robot_namespace, value);
    if (!why.empty()) return refused(tag, value, why);
  }
  return "";
}

}  // namespace

std::string invalidPluginName(const std::vector<ModelPluginType>& types,
                              const std::vector<SensorPluginType>& sensor_types,
                              const std::string& spawned_xml, ModelFormat format,
                              const std::string& robot_namespace) {
  const std::string model_xml = withRobotNamespace(spawned_xml, robot_namespace);
  auto known = [](const auto& registered, const std::string& filename) {
    return std::any_of(registered.begin(), registered.end(),
                       [&](const auto& type) { return type.filename == filename; });
  };
  for (const PluginElement& element : findModelPlugins(model_xml, format)) {
    if (!known(types, element.filename)) continue;
    const std::string why = invalidNameIn(element, "");
    if (!why.empty()) return why;
  }
  for (const SensorElement& sensor : findSensors(model_xml, format)) {
    if (!sensor.error.empty()) continue;
    for (const PluginElement& element : sensor.plugins) {
      if (!known(sensor_types, element.filename)) continue;
      const std::string why = invalidNameIn(element, " of sensor '" + sensor.name + "'");
      if (!why.empty()) return why;
    }
  }
  return "";
}

namespace {

ModelPluginContext pluginContext(const std::string& model, const PluginElement& element,
                                 const std::string& model_xml, ModelFormat format,
                                 const World& world, const LockWorld& lock_world) {
  ModelPluginContext context;
  context.model = model;
  context.name = element.name;
  context.filename = element.filename;
  context.plugin_xml = element.xml;
  context.model_xml = model_xml;
  context.format = format;
  context.robot_namespace = element.robot_namespace;
  context.node = ros::NodeHandle(element.robot_namespace.empty() ? "/" : element.robot_namespace);
  context.world = &world;
  context.lock_world = lock_world;
  return context;
}

// What keeps a plugin or sensor of one model from working: logged, and kept for the spawn's
// answer. Each unknown plugin filename and sensor type is said once.
struct Problems {
  std::vector<std::string>* said;
  std::set<std::string> plugins, sensor_types;
  void error(const std::string& text) {
    ROS_ERROR_STREAM(text);
    said->push_back(text);
  }
  void warn(const std::string& text) {
    ROS_WARN_STREAM(text);
    said->push_back(text);
  }
  void plugin(const std::string& model, const PluginElement& element, const std::string& where) {
    if (plugins.insert(element.filename).second)
      error("model '" + model + "': Failed to load plugin " + element.filename + " (plugin '" +
            element.name + "'" + where +
            "): this simulator has no such plugin; the model works without it");
  }
};

void createSensorPlugins(const std::vector<SensorPluginType>& types, const std::string& model,
                         const SensorElement& sensor, const std::string& model_xml,
                         ModelFormat format, const World& world, const LockWorld& lock_world,
                         Problems* problems, std::vector<std::unique_ptr<ModelPlugin>>* created) {
  const std::string label = "model '" + model + "': sensor '" + sensor.name + "'";
  if (!sensor.error.empty()) {
    problems->error(label + " is ignored, with its plugins: " + sensor.error);
    return;
  }
  bool known_type = false;
  for (const SensorPluginType& type : types)
    for (const std::string& sensor_type : type.sensor_types)
      known_type = known_type || sensor_type == sensor.type;
  if (!known_type) {
    if (problems->sensor_types.insert(sensor.type).second)
      problems->warn(label + " (type " + sensor.type + ") on link '" + sensor.link +
                     "': sensors of type " + sensor.type + " are not simulated here and are "
                     "ignored, with their plugins; the model works without them");
    return;
  }
  {
    std::unique_lock<std::mutex> lock = lock_world();
    LinkInfo info;
    if (!world.linkProperties(model + "::" + sensor.link, &info).ok()) {
      lock.unlock();
      problems->error(label + " is ignored, with its plugins: its link '" + sensor.link +
                      "' is not a link of the model");
      return;
    }
  }
  for (const PluginElement& element : sensor.plugins) {
    const SensorPluginType* type = nullptr;
    for (const SensorPluginType& candidate : types)
      if (candidate.filename == element.filename) type = &candidate;
    if (!type) {
      problems->plugin(model, element, " of sensor '" + sensor.name + "'");
      continue;
    }
    if (std::find(type->sensor_types.begin(), type->sensor_types.end(), sensor.type) ==
        type->sensor_types.end()) {
      std::string wanted;
      for (const std::string& t : type->sensor_types) wanted += (wanted.empty() ? "" : " or ") + t;
      problems->error(element.filename + " for " + label + " not started: it publishes a " +
                      wanted + " sensor, and this one is " + sensor.type);
      continue;
    }
    SensorPluginContext context{
        pluginContext(model, element, model_xml, format, world, lock_world), sensor};
    std::string error;
    std::unique_ptr<ModelPlugin> plugin = type->create(context, &error);
    if (plugin) created->push_back(std::move(plugin));
    else if (!error.empty())
      problems->error(element.filename + " for " + label + " not started: " + error);
  }
}

}  // namespace

std::vector<std::unique_ptr<ModelPlugin>> createModelPlugins(
    const std::vector<ModelPluginType>& types, const std::vector<SensorPluginType>& sensor_types,
    const std::string& model, const std::string& spawned_xml, ModelFormat format,
    const std::string& robot_namespace, const World& world, LockWorld lock_world,
    std::vector<std::string>* said) {
  const std::string model_xml = withRobotNamespace(spawned_xml, robot_namespace);
  std::vector<std::unique_ptr<ModelPlugin>> created;
  Problems problems{said, {}, {}};
  for (const PluginElement& element : findModelPlugins(model_xml, format)) {
    const ModelPluginType* type = nullptr;
    for (const ModelPluginType& candidate : types)
      if (candidate.filename == element.filename) type = &candidate;
    if (!type) {
      problems.plugin(model, element, "");
      continue;
    }
    std::string error;
    std::unique_ptr<ModelPlugin> plugin = type->create(
        pluginContext(model, element, model_xml, format, world, lock_world), &error);
    if (plugin) created.push_back(std::move(plugin));
    else if (!error.empty())
      problems.error(element.filename + " for model '" + model + "' not started: " + error);
  }
  for (const SensorElement& sensor : findSensors(model_xml, format))
    createSensorPlugins(sensor_types, model, sensor, model_xml, format, world, lock_world,
                        &problems, &created);
  return created;
}

}  // namespace onedof_sim::plugins
