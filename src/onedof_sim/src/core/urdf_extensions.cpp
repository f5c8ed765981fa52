#include "urdf_extensions.h"

#include <tinyxml2.h>

#include "onedof_sim/text_number.h"
#include "onedof_sim/trim.h"

namespace onedof_sim {
namespace core {
namespace {

// A coefficient's text as a number, or a refusal naming the link and the element.
Status coefficient(const tinyxml2::XMLElement& element, const std::string& link,
                   std::optional<double>* out) {
  const std::string text = trimmed(element.GetText());
  double value = 0;
  if (!numberIn(text, &value))
    return rejected("link '" + link + "': <gazebo reference> <" + element.Name() + "> '" + text +
                    "' is not a number");
  *out = value;
  return {};
}

}  // namespace

Status urdfLinkExtensions(const std::string& xml, std::map<std::string, UrdfLinkExtension>* out) {
  out->clear();
  tinyxml2::XMLDocument document;
  if (document.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) return {};
  const tinyxml2::XMLElement* robot = document.FirstChildElement("robot");
  if (!robot) return {};
  for (const tinyxml2::XMLElement* gazebo = robot->FirstChildElement("gazebo"); gazebo;
       gazebo = gazebo->NextSiblingElement("gazebo")) {
    const char* reference = gazebo->Attribute("reference");
    if (!reference) continue;
    UrdfLinkExtension& link = (*out)[reference];
    if (const tinyxml2::XMLElement* material = gazebo->FirstChildElement("material")) {
      const std::string name = trimmed(material->GetText());
      if (!name.empty()) link.material = name;
    }
    for (const auto& [tag, value] : {std::pair{"mu1", &link.mu1}, std::pair{"mu2", &link.mu2}}) {
      if (const tinyxml2::XMLElement* element = gazebo->FirstChildElement(tag)) {
        Status status = coefficient(*element, reference, value);
        if (!status.ok()) return status;
      }
    }
  }
  return {};
}

}  // namespace core
}  // namespace onedof_sim
