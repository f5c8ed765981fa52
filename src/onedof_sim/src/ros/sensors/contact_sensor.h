// Gazebo's contact sensor (`contact`): its <contact> element, and the contacts of its
// collisions gathered step by step through World::contacts, as Gazebo's ContactSensor gathers
// the contact manager's messages.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include <onedof_sim/world.h>

namespace onedof_sim::plugins {

// <contact>: the collisions of the sensor's link it watches (<collision>, each by its name on the
// link) and its <topic> (Gazebo's own transport's, read and not used here).
struct ContactConfig {
  std::vector<std::string> collisions;
  std::string topic;
};

// Reads the <contact> of a <sensor> element (its XML text); false, with *error, when the text is
// not XML or a <collision> is empty. No <contact> or no <collision>: no collisions (Gazebo's
// sensor then watches its default "__default__", which no collision is, and reports none).
bool readContactConfig(const std::string& sensor_xml, ContactConfig* config, std::string* error);

// The contacts of one step that involve the sensor's collisions, each with one of them as
// collision1, and the orientation of the sensor's link then (Gazebo gives each contact's wrench
// in its link's frame).
struct StepContacts {
  int64_t time_ns = 0;
  Quat link_orientation;
  std::vector<Contact> contacts;
};

// Gathers a contact sensor's contacts after every step, keeping those of the last kMaxSteps
// steps, as Gazebo's sensor keeps the last 100 of the contact manager's per-step messages; an
// update of the sensor takes what was gathered since the last.
class ContactGatherer {
 public:
  static constexpr size_t kMaxSteps = 100;

  // collisions: scoped "model::link::collision"; link: the sensor's, scoped "model::link".
  ContactGatherer(std::vector<std::string> collisions, std::string link);

  // The world's contacts after the step that reached `time_ns` (none, should it refuse a name:
  // the caller gives only collisions the world has, see World::contacts).
  void gather(const World& world, int64_t time_ns);
  // What was gathered since the last take, oldest first.
  std::vector<StepContacts> take();
  void clear() { steps_.clear(); }

 private:
  std::vector<std::string> collisions_;
  std::string link_;
  std::deque<StepContacts> steps_;
};

}  // namespace onedof_sim::plugins
