#include "model_plugins.h"

#include <set>
#include <utility>

#include <tinyxml2.h>

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
      found.push_back({attribute(sensor, "name"), attribute(sensor, "type"), link});
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

std::vector<std::unique_ptr<ModelPlugin>> createModelPlugins(
    const std::vector<ModelPluginType>& types, const std::string& model,
    const std::string& spawned_xml, ModelFormat format, const std::string& robot_namespace,
    const World& world, LockWorld lock_world) {
  const std::string model_xml = withRobotNamespace(spawned_xml, robot_namespace);
  std::set<std::pair<std::string, std::string>> sensors;  // (name, type) logged
  for (const SensorElement& sensor : findSensors(model_xml, format))
    if (sensors.insert({sensor.name, sensor.type}).second)
      ROS_WARN_STREAM("model '" << model << "': sensor '" << sensor.name << "' (type "
                      << sensor.type << ") on link '" << sensor.link << "' is not simulated "
                      << "here and is ignored, with its plugins; the model works without it");
  std::vector<std::unique_ptr<ModelPlugin>> created;
  std::set<std::string> unknown;
  for (const PluginElement& element : findModelPlugins(model_xml, format)) {
    const ModelPluginType* type = nullptr;
    for (const ModelPluginType& candidate : types)
      if (candidate.filename == element.filename) type = &candidate;
    if (!type) {
      if (unknown.insert(element.filename).second)
        ROS_WARN_STREAM("model '" << model << "': plugin '" << element.name << "' ("
                        << element.filename << ") is not simulated here and is ignored; the "
                        << "model works without it");
      continue;
    }
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
    std::string error;
    std::unique_ptr<ModelPlugin> plugin = type->create(context, &error);
    if (plugin) created.push_back(std::move(plugin));
    else if (!error.empty())
      ROS_ERROR_STREAM(element.filename << " for model '" << model << "' not started: " << error);
  }
  return created;
}

}  // namespace onedof_sim::plugins
