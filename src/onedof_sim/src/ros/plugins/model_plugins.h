// The plugins a spawned model names, created from the registry.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "model_plugin.h"

namespace onedof_sim::plugins {

// A <plugin> element of a model description.
struct PluginElement {
  std::string name;
  std::string filename;
  std::string xml;              // the element, as XML text
  std::string robot_namespace;  // its <robotNamespace>, or empty
};

// The model plugins a URDF (<gazebo><plugin>, with or without a reference) or an SDF
// (<model><plugin>) names, in document order. Sensor plugins (inside <sensor>) are not among them.
std::vector<PluginElement> findModelPlugins(const std::string& model_xml, ModelFormat format);

// A <sensor> element of a model description: no sensor is simulated here.
struct SensorElement {
  std::string name;
  std::string type;
  std::string link;  // URDF: its <gazebo reference>; SDF: its <link>
};

// The sensors a URDF (<gazebo reference="link"><sensor>) or an SDF (<model><link><sensor>) names,
// in document order.
std::vector<SensorElement> findSensors(const std::string& model_xml, ModelFormat format);

// The model description with `robot_namespace` as the <robotNamespace> of every <plugin> that
// has none, as Gazebo's spawn services give a spawn request's robot_namespace to the model's
// plugins; the description unchanged when robot_namespace is empty (or is not XML).
std::string withRobotNamespace(const std::string& model_xml, const std::string& robot_namespace);

// Creates the plugins `model` names, unlocked, from `types` (the registry, and any a caller adds),
// each plugin without a <robotNamespace> of its own in `robot_namespace` (the spawn request's;
// empty: none). A filename no type has is logged once, by name, and the model keeps going
// without it, as Gazebo does; so is a plugin that refuses its <plugin> or its model. Each sensor
// the model names is logged once too, by name and type, with its plugins: none is simulated.
std::vector<std::unique_ptr<ModelPlugin>> createModelPlugins(
    const std::vector<ModelPluginType>& types, const std::string& model,
    const std::string& model_xml, ModelFormat format, const std::string& robot_namespace,
    const World& world, LockWorld lock_world);

}  // namespace onedof_sim::plugins
