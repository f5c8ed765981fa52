#include "contact_sensor.h"

#include <tinyxml2.h>
#include <utility>

#include <onedof_sim/trim.h>

#include "sensor_xml.h"

namespace onedof_sim::plugins {

bool readContactConfig(const std::string& sensor_xml, ContactConfig* config, std::string* error) {
  tinyxml2::XMLDocument doc;
  const tinyxml2::XMLElement* sensor = parseSensor(sensor_xml, &doc, error);
  if (!sensor) return false;
  ContactConfig c;
  const tinyxml2::XMLElement* contact = sensor->FirstChildElement("contact");
  if (contact) {
    for (const auto* collision = contact->FirstChildElement("collision"); collision;
         collision = collision->NextSiblingElement("collision")) {
      // SDF 1.0's <collision name="..."/> as well as <collision>NAME</collision>.
      const char* attribute = collision->Attribute("name");
      const std::string name = trimmed(attribute ? attribute : collision->GetText());
      if (name.empty()) {
        *error = "a <contact><collision> names no collision";
        return false;
      }
      c.collisions.push_back(name);
    }
    if (const auto* topic = contact->FirstChildElement("topic")) c.topic = trimmed(topic->GetText());
  }
  *config = c;
  return true;
}

ContactGatherer::ContactGatherer(std::vector<std::string> collisions, std::string link)
    : collisions_(std::move(collisions)), link_(std::move(link)) {}

void ContactGatherer::gather(const World& world, int64_t time_ns) {
  StepContacts step;
  step.time_ns = time_ns;
  if (!world.contacts(collisions_, &step.contacts).ok()) step.contacts.clear();
  Pose pose;
  Twist unused;
  if (world.linkState(link_, "", &pose, &unused).ok()) step.link_orientation = pose.orientation;
  steps_.push_back(std::move(step));
  if (steps_.size() > kMaxSteps) steps_.pop_front();
}

std::vector<StepContacts> ContactGatherer::take() {
  std::vector<StepContacts> taken(std::make_move_iterator(steps_.begin()),
                                  std::make_move_iterator(steps_.end()));
  steps_.clear();
  return taken;
}

}  // namespace onedof_sim::plugins
