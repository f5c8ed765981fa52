#include "plugin_params.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include <onedof_sim/text_number.h>
#include <onedof_sim/trim.h>
#include <ros/console.h>

#include "sensors/sensor_noise.h"

namespace onedof_sim::plugins {
namespace {

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

}  // namespace

PluginParams::PluginParams(const std::string& plugin_xml, std::string label)
    : label_(std::move(label)) {
  if (doc_.Parse(plugin_xml.c_str(), plugin_xml.size()) == tinyxml2::XML_SUCCESS)
    plugin_ = doc_.FirstChildElement("plugin");
}

bool PluginParams::has(const char* tag) const {
  return plugin_ && plugin_->FirstChildElement(tag);
}

std::string PluginParams::text(const char* tag, const std::string& fallback) const {
  if (!has(tag)) return fallback;
  return trimmed(plugin_->FirstChildElement(tag)->GetText());
}

bool PluginParams::number(const char* tag, double fallback, double* value,
                          std::string* error) const {
  *value = fallback;
  if (!has(tag)) return true;
  const std::string raw = text(tag, "");
  double parsed = 0;
  if (!numberIn(raw, &parsed) || !std::isfinite(parsed)) {
    *error = "<" + std::string(tag) + "> is '" + raw + "', not a number";
    return false;
  }
  *value = parsed;
  return true;
}

bool PluginParams::vector(const char* tag, Vec3* value, std::string* error) const {
  if (!has(tag)) return true;
  const std::string raw = text(tag, "");
  std::istringstream in(raw);
  Vec3 parsed;
  std::string rest;
  if (!(in >> parsed.x >> parsed.y >> parsed.z) || (in >> rest) || !std::isfinite(parsed.x) ||
      !std::isfinite(parsed.y) || !std::isfinite(parsed.z)) {
    *error = "<" + std::string(tag) + "> is '" + raw + "', not three numbers";
    return false;
  }
  *value = parsed;
  return true;
}

bool readFlag(const std::string& text, bool* value) {
  const std::string word = lower(text);
  const bool is_true = word == "true" || word == "1";
  if (!is_true && word != "false" && word != "0") return false;
  *value = is_true;
  return true;
}

bool PluginParams::flag(const char* tag, bool fallback) const {
  if (!has(tag)) return fallback;
  bool value = fallback;
  if (readFlag(text(tag, ""), &value)) return value;
  ROS_WARN_STREAM(label_ << ": <" << tag << "> must be either true or false but is '"
                  << text(tag, "") << "'; it stays " << (fallback ? "true" : "false"));
  return fallback;
}

std::string resolveTfFrame(const std::string& tf_prefix, const std::string& name) {
  if (!name.empty() && name.front() == '/') return name.substr(1);
  if (tf_prefix.empty()) return name;
  const std::string prefix = tf_prefix.front() == '/' ? tf_prefix.substr(1) : tf_prefix;
  return prefix.empty() ? name : prefix + "/" + name;
}

std::string tfPrefix(ros::NodeHandle& node) {
  std::string key, prefix;
  if (node.searchParam("tf_prefix", key)) node.getParam(key, prefix);
  return prefix;
}

bool jointLinks(const ModelPluginContext& context, const std::string& joint, std::string* parent,
                std::string* child) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(context.model_xml.c_str(), context.model_xml.size()) != tinyxml2::XML_SUCCESS)
    return false;
  const bool urdf = context.format == ModelFormat::Urdf;
  const tinyxml2::XMLElement* holder = nullptr;
  if (urdf) {
    holder = doc.FirstChildElement("robot");
  } else if (const auto* sdf = doc.FirstChildElement("sdf")) {
    holder = sdf->FirstChildElement("model");
  }
  if (!holder) return false;
  for (auto* element = holder->FirstChildElement("joint"); element;
       element = element->NextSiblingElement("joint")) {
    const char* name = element->Attribute("name");
    if (!name || joint != name) continue;
    const auto* parent_element = element->FirstChildElement("parent");
    const auto* child_element = element->FirstChildElement("child");
    if (!parent_element || !child_element) return false;
    if (urdf) {
      *parent = parent_element->Attribute("link") ? parent_element->Attribute("link") : "";
      *child = child_element->Attribute("link") ? child_element->Attribute("link") : "";
    } else {
      *parent = trimmed(parent_element->GetText());
      *child = trimmed(child_element->GetText());
    }
    return !parent->empty() && !child->empty();
  }
  return false;
}

uint64_t pluginSeed(const ModelPluginContext& context) {
  return seedOf(context.model + "::" + context.name + "::" + context.filename);
}

void applyRosDebugLevel(const std::string& level) {
  const std::string name = lower(level);
  ros::console::Level value;
  if (name == "debug") value = ros::console::levels::Debug;
  else if (name == "info") value = ros::console::levels::Info;
  else if (name == "warn") value = ros::console::levels::Warn;
  else if (name == "error") value = ros::console::levels::Error;
  else if (name == "fatal") value = ros::console::levels::Fatal;
  else return;
  if (ros::console::set_logger_level(ROSCONSOLE_DEFAULT_NAME, value))
    ros::console::notifyLoggerLevelsChanged();
}

}  // namespace onedof_sim::plugins
