#include "robot_hw_sim.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include <tinyxml2.h>

#include "onedof_sim/text_number.h"
#include "onedof_sim/trim.h"

namespace onedof_sim::control {

namespace {

constexpr const char* kPluginFile = "libgazebo_ros_control.so";

std::string childText(const tinyxml2::XMLElement* element, const char* name) {
  const tinyxml2::XMLElement* child = element->FirstChildElement(name);
  return child ? trimmed(child->GetText()) : "";
}

// Both spellings transmissions use: "hardware_interface/EffortJointInterface" and the bare name.
std::optional<JointInterface> parseInterface(std::string name) {
  const std::string prefix = "hardware_interface/";
  if (name.compare(0, prefix.size(), prefix) == 0) name = name.substr(prefix.size());
  if (name == "EffortJointInterface") return JointInterface::Effort;
  if (name == "PositionJointInterface") return JointInterface::Position;
  if (name == "VelocityJointInterface") return JointInterface::Velocity;
  return std::nullopt;
}

std::vector<JointInterface> interfacesOf(const tinyxml2::XMLElement* element,
                                         const std::string& where,
                                         std::vector<std::string>* warnings) {
  std::vector<JointInterface> interfaces;
  for (auto* hw = element->FirstChildElement("hardwareInterface"); hw;
       hw = hw->NextSiblingElement("hardwareInterface")) {
    const std::string name = trimmed(hw->GetText());
    if (auto interface = parseInterface(name)) interfaces.push_back(*interface);
    else warnings->push_back(where + ": hardware interface '" + name + "' is not one this simulator offers (EffortJointInterface, PositionJointInterface, VelocityJointInterface)");
  }
  return interfaces;
}

const tinyxml2::XMLElement* findPlugin(const tinyxml2::XMLElement* robot) {
  for (auto* gazebo = robot->FirstChildElement("gazebo"); gazebo;
       gazebo = gazebo->NextSiblingElement("gazebo"))
    for (auto* plugin = gazebo->FirstChildElement("plugin"); plugin;
         plugin = plugin->NextSiblingElement("plugin")) {
      const char* file = plugin->Attribute("filename");
      if (file && std::strstr(file, kPluginFile)) return plugin;
    }
  return nullptr;
}

}  // namespace

std::string interfaceTypeName(JointInterface interface) {
  switch (interface) {
    case JointInterface::Effort: return "hardware_interface::EffortJointInterface";
    case JointInterface::Position: return "hardware_interface::PositionJointInterface";
    case JointInterface::Velocity: return "hardware_interface::VelocityJointInterface";
  }
  return "";
}

bool readRobotControlSpec(const std::string& urdf, const std::string& model_name,
                          RobotControlSpec* spec, std::string* error) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(urdf.c_str(), urdf.size()) != tinyxml2::XML_SUCCESS) return false;
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) return false;
  const tinyxml2::XMLElement* plugin = findPlugin(robot);
  if (!plugin) return false;

  RobotControlSpec read;
  read.robot_namespace = childText(plugin, "robotNamespace");
  if (read.robot_namespace.empty()) read.robot_namespace = model_name;
  if (read.robot_namespace.front() != '/') read.robot_namespace = "/" + read.robot_namespace;
  const std::string period = childText(plugin, "controlPeriod");
  if (!period.empty()) {
    double seconds = 0;
    if (!numberIn(period, &seconds) || !std::isfinite(seconds) || seconds <= 0) {
      *error = "gazebo_ros_control: controlPeriod '" + period + "' is not a positive number of seconds";
      return true;
    }
    read.control_period = seconds;
  }

  for (auto* transmission = robot->FirstChildElement("transmission"); transmission;
       transmission = transmission->NextSiblingElement("transmission")) {
    const std::string name = transmission->Attribute("name") ? transmission->Attribute("name") : "";
    const std::string where = "transmission '" + name + "'";
    std::string type = childText(transmission, "type");
    if (type.empty() && transmission->Attribute("type")) type = transmission->Attribute("type");
    if (type != "transmission_interface/SimpleTransmission") {
      read.warnings.push_back(where + " of type '" + type + "' is left out: only transmission_interface/SimpleTransmission is simulated");
      continue;
    }
    const tinyxml2::XMLElement* joint = transmission->FirstChildElement("joint");
    if (!joint || !joint->Attribute("name")) {
      read.warnings.push_back(where + " has no <joint name=...> and is left out");
      continue;
    }
    if (joint->NextSiblingElement("joint")) {
      read.warnings.push_back(where + " has more than one joint: a SimpleTransmission has one; it is left out");
      continue;
    }
    TransmissionJoint entry;
    entry.transmission = name;
    entry.joint = joint->Attribute("name");
    entry.interfaces = interfacesOf(joint, where, &read.warnings);
    const tinyxml2::XMLElement* actuator = transmission->FirstChildElement("actuator");
    if (entry.interfaces.empty() && actuator) {
      // Older URDFs name the interface on the actuator; gazebo_ros_control still takes it there.
      entry.interfaces = interfacesOf(actuator, where, &read.warnings);
    }
    if (actuator) {
      const std::string reduction = childText(actuator, "mechanicalReduction");
      if (!reduction.empty()) entry.mechanical_reduction = std::atof(reduction.c_str());
    }
    if (entry.interfaces.empty()) {
      read.warnings.push_back(where + " names no hardware interface this simulator offers and is left out");
      continue;
    }
    read.joints.push_back(entry);
  }
  *spec = read;
  return true;
}

RobotHwSim::RobotHwSim(const World& world, const std::string& model,
                       const RobotControlSpec& spec, std::vector<std::string>* warnings) {
  for (const TransmissionJoint& transmission : spec.joints) {
    SimJoint handle;
    handle.name = transmission.joint;
    handle.world_name = model + "::" + transmission.joint;
    handle.interfaces = transmission.interfaces;
    JointInfo info;
    if (!world.jointInfo(handle.world_name, &info).ok()) {
      warnings->push_back("transmission '" + transmission.transmission + "': joint '" +
                          transmission.joint + "' is not in model '" + model + "'; left out");
      continue;
    }
    if (info.type == JointType::Fixed) {
      warnings->push_back("transmission '" + transmission.transmission + "': joint '" +
                          transmission.joint + "' is fixed and takes no effort; left out");
      continue;
    }
    handle.type = info.type;
    handle.has_limits = info.has_limits;
    handle.lower = info.lower;
    handle.upper = info.upper;
    handle.position = info.position;
    joints_.push_back(handle);
  }
}

std::vector<JointStateHandle> RobotHwSim::jointStates() const {
  return std::vector<JointStateHandle>(joints_.begin(), joints_.end());
}

std::optional<JointStateHandle> RobotHwSim::jointState(const std::string& name) const {
  for (const SimJoint& joint : joints_)
    if (joint.name == name) return JointStateHandle(joint);
  return std::nullopt;
}

std::optional<EffortJointHandle> RobotHwSim::effortJoint(const std::string& name) {
  for (SimJoint& joint : joints_)
    if (joint.name == name && std::find(joint.interfaces.begin(), joint.interfaces.end(),
                                        JointInterface::Effort) != joint.interfaces.end())
      return EffortJointHandle(joint);
  return std::nullopt;
}

void RobotHwSim::read(const World& world) {
  for (SimJoint& handle : joints_) {
    JointInfo info;
    if (!world.jointInfo(handle.world_name, &info).ok()) continue;
    handle.position = info.position;
    handle.velocity = info.rate;
  }
}

void RobotHwSim::clearCommands() {
  for (SimJoint& handle : joints_) handle.effort_command.reset();
}

void RobotHwSim::write(World& world) {
  for (SimJoint& handle : joints_) {
    handle.effort = 0;
    if (!handle.effort_command) continue;
    JobOutcome outcome;
    // Refused only for a non-finite effort: that step goes without it, as Gazebo's SetForce
    // would not take it either.
    if (!world.setJointEffortCommand(handle.world_name, *handle.effort_command, &outcome).ok())
      continue;
    handle.effort = outcome.safe_effort ? std::copysign(*outcome.safe_effort, *handle.effort_command)
                    : outcome.effort_limit ? std::copysign(*outcome.effort_limit, *handle.effort_command)
                                           : *handle.effort_command;
  }
}

}  // namespace onedof_sim::control
