// Reading a <sensor> element as Gazebo's SDF reader takes it: its XML, one number in a tag,
// finite, the tag naming itself in the error when it is not; a <pose>'s six.
#pragma once

#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <sstream>
#include <string>

#include <onedof_sim/pose_math.h>
#include <onedof_sim/text_number.h>
#include <onedof_sim/trim.h>
#include <onedof_sim/world.h>
#include <tinyxml2.h>

namespace onedof_sim::plugins {

// The element at `names` below `element` (each the first child of that name), or null.
inline const tinyxml2::XMLElement* sensorPath(const tinyxml2::XMLElement* element,
                                             std::initializer_list<const char*> names) {
  for (const char* name : names) element = element ? element->FirstChildElement(name) : nullptr;
  return element;
}

// Parses a <sensor> element's XML text into *doc: its root, or null with *error when the text is
// not XML.
inline const tinyxml2::XMLElement* parseSensor(const std::string& sensor_xml,
                                               tinyxml2::XMLDocument* doc, std::string* error) {
  if (doc->Parse(sensor_xml.c_str(), sensor_xml.size()) == tinyxml2::XML_SUCCESS &&
      doc->RootElement())
    return doc->RootElement();
  *error = "the <sensor> is not XML";
  return nullptr;
}

// The <tag> a <sensor> element's XML text must hold (<ray>, <camera>), parsed into *doc; null with
// *error when the text is not XML or has no <tag>.
inline const tinyxml2::XMLElement* requiredSensorChild(const std::string& sensor_xml,
                                                       const char* tag,
                                                       tinyxml2::XMLDocument* doc,
                                                       std::string* error) {
  const tinyxml2::XMLElement* sensor = parseSensor(sensor_xml, doc, error);
  if (!sensor) return nullptr;
  const tinyxml2::XMLElement* child = sensor->FirstChildElement(tag);
  if (!child) *error = "it has no <" + std::string(tag) + ">";
  return child;
}

// The number in `parent`'s <tag>, left as it is when there is none; false, with *error naming
// "<where><tag>", when its text is not a finite number.
inline bool readSensorNumber(const tinyxml2::XMLElement* parent, const char* tag,
                             const std::string& where, double* value, std::string* error) {
  const tinyxml2::XMLElement* child = parent ? parent->FirstChildElement(tag) : nullptr;
  if (!child) return true;
  const std::string text = trimmed(child->GetText());
  double parsed = 0;
  if (!numberIn(text, &parsed) || !std::isfinite(parsed)) {
    *error = "<" + where + "><" + tag + "> is '" + text + "', not a number";
    return false;
  }
  *value = parsed;
  return true;
}

// An SDF <pose>'s text, "x y z roll pitch yaw" (fixed-axis roll, pitch, yaw): false, *pose
// untouched, when it is not six finite numbers.
inline bool readPoseText(const std::string& text, Pose* pose) {
  std::istringstream in(text);
  Vec3 xyz, rpy;
  std::string rest;
  if (!(in >> xyz.x >> xyz.y >> xyz.z >> rpy.x >> rpy.y >> rpy.z) || (in >> rest) ||
      !isFinite(xyz) || !isFinite(rpy))
    return false;
  *pose = {xyz, fromRpy(rpy)};
  return true;
}

}  // namespace onedof_sim::plugins
