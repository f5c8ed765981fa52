// libgazebo_ros_bumper.so on a `contact` sensor (gazebo_plugins' GazeboRosBumper): the
// contacts of the sensor's <contact><collision>s (names of collisions on its link) as
// gazebo_msgs/ContactsState on <bumperTopicName> (default bumper_states) in the plugin's
// <robotNamespace>, header.frame_id <frameName> (default world, under the tf_prefix), at the
// sensor's <update_rate> of sim time (0: every step) while anyone subscribes; with no contact,
// an empty list. The plugin's <updateRate> and <alwaysOn> are not read, as upstream.
//
// As Gazebo's contact sensor, after every step it gathers that step's contacts of its collisions
// (sensors/contact_sensor.h), those of the last 100 steps kept, and each update publishes what
// it gathered since the last: one ContactState for each pair of collisions in touch at each of
// those steps, oldest first, stamped (header) at the update's sim time. In each: collision1_name
// the sensor's collision and collision2_name the other, scoped model::link::collision (Gazebo's
// ground plane's: ground_plane::link::collision); for each point where they met, the wrench the
// contact put on collision1's link, force and its torque about the link's centre of mass, in the
// link's frame (as Gazebo's contact messages give it; upstream's bumper reads no frame of
// <frameName> and passes it on so), the position and the normal (unit, pushing collision1 out of
// collision2) in the world frame, and the depth of the overlap; total_wrench their sum; info
// upstream's text, the step's time in it.
//
// Where it differs from Gazebo, whose contact pairs come in the physics engine's order: the
// sensor's collision is always collision1, so that its wrenches are always on the sensor's link
// (and the normals push it away from what it touches).
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gazebo_msgs/ContactsState.h>
#include <onedof_sim/pose_math.h>
#include <ros/console.h>

#include "model_plugin.h"
#include "plugin_params.h"
#include "sensor_plugin.h"
#include "sensors/contact_sensor.h"
#include "sensors/update_gate.h"

namespace onedof_sim::plugins {
namespace {

geometry_msgs::Vector3 toVector(const Vec3& v) {
  geometry_msgs::Vector3 out;
  out.x = v.x, out.y = v.y, out.z = v.z;
  return out;
}

class GazeboRosBumper : public ModelPlugin {
 public:
  GazeboRosBumper(const SensorPluginContext& context, std::vector<std::string> collisions,
                  const std::string& topic, const std::string& frame)
      : gatherer_(std::move(collisions), context.plugin.model + "::" + context.sensor.link),
        gate_(context.sensor.update_rate),
        node_(context.plugin.node),
        frame_id_(resolveTfFrame(tfPrefix(node_), frame)),
        publisher_(node_.advertise<gazebo_msgs::ContactsState>(topic, 1)) {}

  void afterStep(World& world, const StepTime& at) override {
    gatherer_.gather(world, at.time_ns);
    if (!gate_.due(at.time_ns)) return;
    const std::vector<StepContacts> steps = gatherer_.take();
    if (publisher_.getNumSubscribers() == 0) return;
    auto message = boost::make_shared<gazebo_msgs::ContactsState>();
    message->header.frame_id = frame_id_;
    message->header.stamp.fromNSec(static_cast<uint64_t>(at.time_ns));
    size_t count = 0;
    for (const StepContacts& step : steps) count += step.contacts.size();
    for (const StepContacts& step : steps)
      for (const Contact& contact : step.contacts)
        message->states.push_back(state(step, contact, message->states.size(), count));
    publications_.add(publisher_, message);
  }

  void reset(World& /*world*/) override {
    gate_.reset();
    gatherer_.clear();
  }

  std::vector<Publication> takePublications() override { return publications_.take(); }

 private:
  static gazebo_msgs::ContactState state(const StepContacts& step, const Contact& contact,
                                         size_t index, size_t count) {
    gazebo_msgs::ContactState state;
    state.collision1_name = contact.collision1;
    state.collision2_name = contact.collision2;
    ros::Time time;
    time.fromNSec(static_cast<uint64_t>(step.time_ns));
    std::ostringstream info;
    info << "Debug:  i:(" << index << "/" << count << ")     my geom:" << contact.collision1
         << "   other geom:" << contact.collision2 << "         time:" << time << std::endl;
    state.info = info.str();
    Wrench total;
    for (const ContactPoint& point : contact.points) {
      const Vec3 force = inFrame(step.link_orientation, point.wrench1.force);
      const Vec3 torque = inFrame(step.link_orientation, point.wrench1.torque);
      geometry_msgs::Wrench wrench;
      wrench.force = toVector(force);
      wrench.torque = toVector(torque);
      state.wrenches.push_back(wrench);
      total.force = total.force + force;
      total.torque = total.torque + torque;
      state.contact_positions.push_back(toVector(point.position));
      state.contact_normals.push_back(toVector(point.normal));
      state.depths.push_back(point.depth);
    }
    state.total_wrench.force = toVector(total.force);
    state.total_wrench.torque = toVector(total.torque);
    return state;
  }

  ContactGatherer gatherer_;
  SensorGate gate_;
  ros::NodeHandle node_;
  std::string frame_id_;
  ros::Publisher publisher_;
  PublicationQueue publications_;
};

}  // namespace

std::unique_ptr<ModelPlugin> makeGazeboRosBumper(const SensorPluginContext& context,
                                                 std::string* error) {
  const PluginParams params(context.plugin.plugin_xml,
                            context.plugin.filename + " (" + context.plugin.model + ")");
  ContactConfig config;
  if (!readContactConfig(context.sensor.xml, &config, error)) return nullptr;
  const std::string label = context.plugin.filename + " of sensor '" + context.sensor.name +
                            "' (model '" + context.plugin.model + "')";
  const std::string link = context.plugin.model + "::" + context.sensor.link;
  std::vector<std::string> collisions;
  {
    std::unique_lock<std::mutex> lock = context.plugin.lock_world();
    for (const std::string& name : config.collisions) {
      std::vector<Contact> unused;
      const std::string scoped = link + "::" + name;
      if (context.plugin.world->contacts({scoped}, &unused).ok())
        collisions.push_back(scoped);
      else
        ROS_WARN_STREAM(label << ": <contact><collision> '" << name << "' is no collision of link '"
                        << context.sensor.link << "': it reports no contacts of it, as Gazebo");
    }
  }
  if (config.collisions.empty())
    ROS_WARN_STREAM(label << ": its <contact> names no <collision>: it reports no contacts, as "
                    "Gazebo's sensor with its default collision");
  return std::make_unique<GazeboRosBumper>(context, collisions,
                                           params.text("bumperTopicName", "bumper_states"),
                                           params.text("frameName", "world"));
}

}  // namespace onedof_sim::plugins
