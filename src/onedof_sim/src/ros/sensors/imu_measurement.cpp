#include "imu_measurement.h"

#include <utility>

#include <onedof_sim/pose_math.h>
#include <onedof_sim/trim.h>
#include <tinyxml2.h>

#include "sensor_xml.h"

namespace onedof_sim::plugins {

ImuMeasurement::ImuMeasurement(std::string link, const Pose& on_link, const Quat& world_turn)
    : link_(std::move(link)), on_link_(on_link), world_turn_(world_turn) {}

bool ImuMeasurement::frameState(const World& world, Pose* frame, Vec3* velocity,
                                Vec3* angular) const {
  Pose link_pose;
  Twist twist;
  if (!world.linkState(link_, "", &link_pose, &twist).ok()) return false;
  *frame = compose(link_pose, on_link_);
  const Vec3 lever{frame->position.x - link_pose.position.x,
                   frame->position.y - link_pose.position.y,
                   frame->position.z - link_pose.position.z};
  const Vec3& w = twist.angular;
  *velocity = {twist.linear.x + (w.y * lever.z - w.z * lever.y),
               twist.linear.y + (w.z * lever.x - w.x * lever.z),
               twist.linear.z + (w.x * lever.y - w.y * lever.x)};
  *angular = w;
  return true;
}

bool ImuMeasurement::restart(const World& world, int64_t time_ns) {
  Pose frame;
  Vec3 velocity, angular;
  if (!frameState(world, &frame, &velocity, &angular)) return false;
  last_time_ns_ = time_ns;
  last_velocity_ = velocity;
  acceleration_ = {};
  return true;
}

bool ImuMeasurement::measure(const World& world, int64_t time_ns, ImuReading* reading) {
  Pose frame;
  Vec3 velocity, angular;
  if (!frameState(world, &frame, &velocity, &angular)) return false;
  const double dt = 1e-9 * static_cast<double>(time_ns - last_time_ns_);
  if (dt > 0) {
    acceleration_ = {(velocity.x - last_velocity_.x) / dt, (velocity.y - last_velocity_.y) / dt,
                     (velocity.z - last_velocity_.z) / dt};
    last_time_ns_ = time_ns;
    last_velocity_ = velocity;
  }
  const Vec3& g = world.params().gravity;
  const Vec3 specific_force{acceleration_.x - g.x, acceleration_.y - g.y, acceleration_.z - g.z};
  reading->orientation = normalized(multiply(world_turn_, frame.orientation));
  reading->angular_velocity = inFrame(reading->orientation, angular);
  reading->linear_acceleration = inFrame(reading->orientation, specific_force);
  return true;
}

bool ImuNoiseParams::any() const {
  for (int i = 0; i < 3; ++i)
    if (rate[i].on || acceleration[i].on) return true;
  return false;
}

bool ImuNoiseParams::drifts() const {
  for (int i = 0; i < 3; ++i)
    if (rate[i].drifts() || acceleration[i].drifts()) return true;
  return false;
}

bool readImuNoise(const std::string& sensor_xml, ImuNoiseParams* params, std::string* error) {
  *params = {};
  tinyxml2::XMLDocument doc;
  const tinyxml2::XMLElement* sensor = parseSensor(sensor_xml, &doc, error);
  if (!sensor) return false;
  const tinyxml2::XMLElement* imu = sensor->FirstChildElement("imu");
  if (!imu) return true;
  if (const tinyxml2::XMLElement* old = imu->FirstChildElement("noise")) {
    // <type> applies to both groups: copied into each as the converted SDF has it.
    const tinyxml2::XMLElement* type = old->FirstChildElement("type");
    const std::string type_text = type ? trimmed(type->GetText()) : "gaussian";
    for (const auto& [group, out] : {std::pair{"rate", params->rate},
                                     std::pair{"accel", params->acceleration}}) {
      tinyxml2::XMLDocument copy;
      tinyxml2::XMLElement* noise = copy.NewElement("noise");
      copy.InsertEndChild(noise);
      noise->SetAttribute("type", type_text.c_str());
      if (const tinyxml2::XMLElement* values = old->FirstChildElement(group))
        for (auto* child = values->FirstChildElement(); child; child = child->NextSiblingElement())
          noise->InsertEndChild(child->DeepClone(&copy));
      NoiseParams axis;
      if (!readNoise(noise, "<imu><noise><" + std::string(group) + ">", &axis, error))
        return false;
      for (int i = 0; i < 3; ++i) out[i] = axis;
    }
  }
  const char* axes[3] = {"x", "y", "z"};
  for (const auto& [group, out] : {std::pair{"angular_velocity", params->rate},
                                   std::pair{"linear_acceleration", params->acceleration}}) {
    const tinyxml2::XMLElement* element = imu->FirstChildElement(group);
    if (!element) continue;
    for (int i = 0; i < 3; ++i) {
      const tinyxml2::XMLElement* axis = element->FirstChildElement(axes[i]);
      const tinyxml2::XMLElement* noise = axis ? axis->FirstChildElement("noise") : nullptr;
      if (!noise) continue;
      if (!readNoise(noise, "<imu><" + std::string(group) + "><" + axes[i] + "><noise>", &out[i],
                     error))
        return false;
    }
  }
  return true;
}

}  // namespace onedof_sim::plugins
