// The sensor seam: what a Gazebo sensor (`<sensor type=... name=...>` in a URDF's
// <gazebo reference="link"> or an SDF <link>) and the plugin inside it that publishes it
// (`<plugin filename="libgazebo_ros_XXX.so">`) are here.
//
// A sensor plugin is a ModelPlugin: created when its model is spawned, destroyed with it, called
// by the loop around every step and handing out its messages through takePublications (see
// model_plugin.h). It is made from the sensor's element as well as its own, measures the sensor
// after a step when its SensorGate (sensors/update_gate.h) says an update is due, and publishes
// what it measured. A sensor plugin is one file in this folder and one entry in registry.cpp.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "model_plugin.h"
#include "sensors/sensor_noise.h"
#include "sensors/update_gate.h"

namespace onedof_sim::plugins {

// A <plugin> element of a model description.
struct PluginElement {
  std::string name;
  std::string filename;
  std::string xml;              // the element, as XML text
  std::string robot_namespace;  // its <robotNamespace>, or empty
};

// A <sensor> element of a model description, read as Gazebo reads it.
struct SensorElement {
  std::string name;
  std::string type;
  std::string link;   // URDF: its <gazebo reference>; SDF: its <link>
  Pose pose;          // <pose> "x y z roll pitch yaw", in the link frame
  double update_rate = 0;  // <update_rate>, Hz of sim time; 0: every step
  bool always_on = false;  // <always_on>
  bool visualize = false;  // <visualize>: accepted, nothing is drawn
  std::string xml;         // the element, as XML text
  std::vector<PluginElement> plugins;  // its <plugin>s, in document order
  std::string error;       // why the element is malformed; empty when it is not
};

// What a sensor plugin is created with: the context a model plugin has (its <plugin>, the model,
// the world) and the sensor it publishes.
struct SensorPluginContext {
  ModelPluginContext plugin;
  SensorElement sensor;
};

using SensorPluginFactory = std::function<std::unique_ptr<ModelPlugin>(const SensorPluginContext&,
                                                                       std::string* error)>;

// A registry entry: the plugin's Gazebo filename, the sensor types it publishes (Gazebo refuses
// it inside any other) and its factory.
struct SensorPluginType {
  std::string filename;
  std::vector<std::string> sensor_types;
  SensorPluginFactory create;
};

// The seed of a sensor's noise: seedOf its scoped name ("model::link::sensor"), the same on
// every run and machine (Gazebo seeds its noise at random), so that runs in lock-step repeat it.
inline uint64_t sensorSeed(const SensorPluginContext& context) {
  return seedOf(context.plugin.model + "::" + context.sensor.link + "::" + context.sensor.name);
}

}  // namespace onedof_sim::plugins
