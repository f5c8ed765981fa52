// The sensor seam: what a Gazebo sensor (`<sensor type=... name=...>` in a URDF's
// <gazebo reference="link"> or an SDF <link>) and the plugin inside it that publishes it
// (`<plugin filename="libgazebo_ros_XXX.so">`) are here.
//
// A sensor plugin is a ModelPlugin: created when its model is spawned, destroyed with it, called
// by the loop around every step and handing out its messages through takePublications (see
// model_plugin.h). It is made from the sensor's element as well as its own, measures the sensor
// after a step when its SensorGate says an update is due, and publishes what it measured. A
// sensor plugin is one file in this folder and one entry in registry.cpp.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
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

// The seed of a sensor's noise: FNV-1a of its scoped name ("model::link::sensor"), the same on
// every run and machine (Gazebo seeds its noise at random), so that runs in lock-step repeat it.
inline uint64_t sensorSeed(const SensorPluginContext& context) {
  const std::string name =
      context.plugin.model + "::" + context.sensor.link + "::" + context.sensor.name;
  uint64_t hash = 14695981039346656037ull;
  for (unsigned char c : name) hash = (hash ^ c) * 1099511628211ull;
  return hash;
}

// When a sensor updates, as Gazebo's Sensor::Update decides over sim time: at a time later than
// the last update, once the time since it, plus what the last update came late, reaches the
// period (1 / update_rate), so that updates keep to the rate's grid whatever the step; a rate of
// 0: every step. The last update starts at time 0, as Gazebo's does, and goes back there on a
// reset (Gazebo's ResetLastUpdateTime): after reset_world the next step updates, after
// reset_simulation the step that reaches a period.
class SensorGate {
 public:
  SensorGate() = default;
  explicit SensorGate(double rate_hz)
      : period_ns_(rate_hz > 0 ? static_cast<int64_t>(std::llround(1e9 / rate_hz)) : 0) {}

  // Whether an update is due at `now_ns`; if so it counts as made.
  bool due(int64_t now_ns) {
    if (now_ns < last_ns_) reset();
    if (now_ns <= last_ns_) return false;
    const int64_t elapsed = period_ns_ > 0 ? now_ns - last_ns_ + delay_ns_ : 0;
    if (elapsed < period_ns_) return false;
    delay_ns_ = elapsed - period_ns_;
    if (delay_ns_ > period_ns_) delay_ns_ = 0;  // too far behind to catch up
    last_ns_ = now_ns;
    return true;
  }

  void reset() {
    last_ns_ = 0;
    delay_ns_ = 0;
  }

 private:
  int64_t period_ns_ = 0;
  int64_t last_ns_ = 0;
  int64_t delay_ns_ = 0;
};

}  // namespace onedof_sim::plugins
