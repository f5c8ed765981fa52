// The quick pass over a model's XML before a parser reads it: its size and element counts against
// the Limits (model_description.h). tinyxml2 reads a thousand links in milliseconds, where
// libsdformat takes seconds.
#include <tinyxml2.h>

#include <cstring>
#include <vector>

#include "model_description.h"

namespace onedof_sim {
namespace core {
namespace {

struct ElementCounts {
  size_t links = 0, joints = 0, includes = 0;
};

bool named(const tinyxml2::XMLElement& element, const char* name) {
  return std::strcmp(element.Name(), name) == 0;
}

// URDF: the <link>s and <joint>s of <robot> (urdfdom reads no others); `world` is not a link of
// the model.
ElementCounts countUrdf(const tinyxml2::XMLElement& robot) {
  ElementCounts counts;
  for (const tinyxml2::XMLElement* e = robot.FirstChildElement(); e; e = e->NextSiblingElement()) {
    const char* name = e->Attribute("name");
    if (named(*e, "link") && !(name && std::strcmp(name, kWorldLink) == 0)) ++counts.links;
    if (named(*e, "joint")) ++counts.joints;
  }
  return counts;
}

// SDF: the <link>s and <joint>s of every <model>, nested ones included, and the <include>s of
// models and worlds. A plugin's own elements of those names are not counted: they are no model's.
ElementCounts countSdf(const tinyxml2::XMLElement& sdf) {
  ElementCounts counts;
  std::vector<const tinyxml2::XMLElement*> containers{&sdf};
  while (!containers.empty()) {
    const tinyxml2::XMLElement* container = containers.back();
    containers.pop_back();
    const bool is_model = named(*container, "model");
    for (const tinyxml2::XMLElement* e = container->FirstChildElement(); e;
         e = e->NextSiblingElement()) {
      if (named(*e, "model") || (named(*e, "world") && !is_model)) containers.push_back(e);
      else if (named(*e, "include")) ++counts.includes;
      else if (is_model && named(*e, "link")) ++counts.links;
      else if (is_model && named(*e, "joint")) ++counts.joints;
    }
  }
  return counts;
}

Status tooMany(size_t count, const std::string& what, size_t limit) {
  return rejected("the model has " + std::to_string(count) + " " + what + "; at most " +
                  std::to_string(limit) + " are accepted");
}

}  // namespace

Status precheckModelXml(const std::string& xml, ModelFormat format) {
  if (xml.size() > kMaxModelXmlBytes)
    return rejected("the model XML has " + std::to_string(xml.size()) + " bytes; at most " +
                    std::to_string(kMaxModelXmlBytes) + " are accepted");
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS || !doc.RootElement()) return {};
  const ElementCounts counts =
      format == ModelFormat::Urdf ? countUrdf(*doc.RootElement()) : countSdf(*doc.RootElement());
  if (counts.links > kMaxModelLinks) return tooMany(counts.links, "links", kMaxModelLinks);
  // Each joint moves a link of its own, so a model within the link limit has no more joints.
  if (counts.joints > kMaxModelLinks) return tooMany(counts.joints, "joints", kMaxModelLinks);
  if (counts.includes > kMaxModelIncludes)
    return tooMany(counts.includes, "<include>s", kMaxModelIncludes);
  return {};
}

}  // namespace core
}  // namespace onedof_sim
