// The plugins a spawned model names, created from the registry.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "model_plugin.h"
#include "sensor_plugin.h"

namespace onedof_sim::plugins {

// The model plugins a URDF (<gazebo><plugin>, with or without a reference) or an SDF
// (<model><plugin>) names, in document order. Sensor plugins (inside <sensor>) are not among them.
std::vector<PluginElement> findModelPlugins(const std::string& model_xml, ModelFormat format);

// The sensors a URDF (<gazebo reference="link"><sensor>) or an SDF (<model><link><sensor>) names,
// in document order, each with its plugins.
std::vector<SensorElement> findSensors(const std::string& model_xml, ModelFormat format);

// The model description with `robot_namespace` as the <robotNamespace> of every <plugin> that
// has none, as Gazebo's spawn services give a spawn request's robot_namespace to the model's
// plugins; the description unchanged when robot_namespace is empty (or is not XML).
std::string withRobotNamespace(const std::string& model_xml, const std::string& robot_namespace);

// Why a plugin `model_xml` names from `types` or `sensor_types` could not be started under its
// ROS names, empty when every one can: roscpp refuses (throws) a namespace, topic or service name
// that is not a valid graph resource name (a space, a non-ASCII letter, "::", a leading digit).
// The names are a plugin's <robotNamespace> (or `robot_namespace`, the spawn request's, where it
// has none), its <cameraName> (a namespace under that one) and every parameter whose tag ends in
// Topic, TopicName or ServiceName, the names gazebo_ros's plugins take. Checked before the model
// enters the world, so that a spawn is refused whole.
std::string invalidPluginName(const std::vector<ModelPluginType>& types,
                              const std::vector<SensorPluginType>& sensor_types,
                              const std::string& model_xml, ModelFormat format,
                              const std::string& robot_namespace);

// Creates the plugins `model` names, unlocked, from `types` (the registry, and any a caller adds),
// and the plugins of its sensors from `sensor_types`, each plugin without a <robotNamespace> of
// its own in `robot_namespace` (the spawn request's; empty: none). A filename no type has is
// logged once, by name, and the model keeps going without it, as Gazebo does; so is a plugin that
// refuses its <plugin> or its model, a sensor type no sensor plugin publishes (by type, with the
// sensor's name), and a malformed <sensor> or one on a link the model lacks (an error, naming
// what is wrong); each of those reasons is also added to *problems, for the spawn's answer.
// Throws what a plugin's constructor throws (roscpp's ros::Exception for a name it refuses),
// having destroyed the plugins it made.
std::vector<std::unique_ptr<ModelPlugin>> createModelPlugins(
    const std::vector<ModelPluginType>& types, const std::vector<SensorPluginType>& sensor_types,
    const std::string& model,
    const std::string& model_xml, ModelFormat format, const std::string& robot_namespace,
    const World& world, LockWorld lock_world, std::vector<std::string>* problems);

}  // namespace onedof_sim::plugins
