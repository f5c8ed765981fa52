// A model plugin's <plugin> element read as gazebo_ros's plugins read theirs (GazeboRos's
// getParameter and getParameterBoolean), and the URDF or SDF facts they look up in the model.
#pragma once

#include <cstdint>
#include <string>

#include <tinyxml2.h>

#include "model_plugin.h"

namespace onedof_sim::plugins {

class PluginParams {
 public:
  // `label` names the plugin in what it logs ("gazebo_ros_diff_drive (mobot)").
  PluginParams(const std::string& plugin_xml, std::string label);

  bool has(const char* tag) const;
  // The element's text, trimmed; `fallback` when it is absent.
  std::string text(const char* tag, const std::string& fallback) const;
  // A number; `fallback` when absent. False, with *error naming the tag, when the text is not one.
  bool number(const char* tag, double fallback, double* value, std::string* error) const;
  // Three numbers ("x y z"); *value untouched when absent. False, with *error naming the tag,
  // when the text is not three numbers.
  bool vector(const char* tag, Vec3* value, std::string* error) const;
  // true/false/1/0 in any case, as GazeboRos takes them; anything else is logged and the
  // fallback kept.
  bool flag(const char* tag, bool fallback) const;
  const std::string& label() const { return label_; }

 private:
  tinyxml2::XMLDocument doc_;
  const tinyxml2::XMLElement* plugin_ = nullptr;
  std::string label_;
};

// An SDF or plugin flag: true/false/1/0 in any case, as libsdformat and GazeboRos read them;
// false, *value untouched, for anything else.
bool readFlag(const std::string& text, bool* value);

// The frame name TF gets for `name` under `tf_prefix`, as tf::resolve makes it: a leading '/'
// means absolute (dropped), else the prefix, without its leading '/', and a '/' go before it.
std::string resolveTfFrame(const std::string& tf_prefix, const std::string& name);
// The tf_prefix parameter the plugin's node finds (searchParam), empty if none.
std::string tfPrefix(ros::NodeHandle& node);

// The parent and child links a joint of the model joins, from its URDF or SDF; false if the model
// has no such joint.
bool jointLinks(const ModelPluginContext& context, const std::string& joint, std::string* parent,
                std::string* child);

// The seed of a model plugin's noise generator: seedOf its model, name and filename
// ("model::name::libgazebo_ros_xxx.so"), the same on every run and machine (Gazebo's plugins
// seed theirs at random), so that runs in lock-step repeat their noise and no two plugins of a
// model draw the same.
uint64_t pluginSeed(const ModelPluginContext& context);

// Sets the level of roscpp's default logger as gazebo_ros's <rosDebugLevel> does (Debug, Info,
// Warn, Error, Fatal; anything else leaves it).
void applyRosDebugLevel(const std::string& level);

}  // namespace onedof_sim::plugins
