// Reading a <sensor> element's numbers as Gazebo's SDF reader takes them: one number in a tag,
// finite, the tag naming itself in the error when it is not.
#pragma once

#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <string>

#include <onedof_sim/trim.h>
#include <tinyxml2.h>

namespace onedof_sim::plugins {

// The element at `names` below `element` (each the first child of that name), or null.
inline const tinyxml2::XMLElement* sensorPath(const tinyxml2::XMLElement* element,
                                             std::initializer_list<const char*> names) {
  for (const char* name : names) element = element ? element->FirstChildElement(name) : nullptr;
  return element;
}

// The number in `parent`'s <tag>, left as it is when there is none; false, with *error naming
// "<where><tag>", when its text is not a finite number.
inline bool readSensorNumber(const tinyxml2::XMLElement* parent, const char* tag,
                             const std::string& where, double* value, std::string* error) {
  const tinyxml2::XMLElement* child = parent ? parent->FirstChildElement(tag) : nullptr;
  if (!child) return true;
  const std::string text = trimmed(child->GetText());
  char* end = nullptr;
  const double parsed = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(parsed)) {
    *error = "<" + where + "><" + tag + "> is '" + text + "', not a number";
    return false;
  }
  *value = parsed;
  return true;
}

}  // namespace onedof_sim::plugins
