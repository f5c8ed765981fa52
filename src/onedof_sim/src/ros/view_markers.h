// The world as Gazebo's window draws it, for rviz: one visualization_msgs/MarkerArray topic per
// item of Gazebo's View menu, each a display the user ticks on and off. Under the node's
// namespace (/gazebo/...):
//   visual_markers     every model's <visual>s: primitives, meshes (file:// URIs rviz loads),
//                      Gazebo's named materials and the colours given; a plane at most 20 m across
//   collision_markers  every collision shape, grey and translucent (View > Collisions)
//   joint_markers      each joint's origin, and its axis as an arrow (View > Joints)
//   com_markers        each link's centre of mass, a sphere of lead of its mass (View > Center of
//                      Mass)
//   inertia_markers    each link's box of equal mass and inertia on its principal axes (View >
//                      Inertias)
//   contact_markers    the last step's contact points and their normals (View > Contacts)
// and the window's own streams, at the views' rate, for the window's rviz, panel and model
// handles: /clock and /gazebo/model_states go out at every step a subscriber is there, each
// message a cost to the loop (a write for roscpp's network thread), and the window needs neither
// more often than it draws (Gazebo's window, too, has its poses and world statistics from
// streams of their own, throttled):
//   view_model_states  every model's pose and twist (gazebo_msgs/ModelStates)
//   view_clock         the sim time (rosgraph_msgs/Clock, latched): the window's rviz has it for
//                      its /clock (a remapping), its time moving in the views' steps
// Markers are in the frame `world`, one namespace per model (a checkbox per model in rviz), and
// follow their links: each view is republished while someone subscribes to it, at most
// kViewFrequency times per second of sim time (and kMaxViewFrequency per wall second, for a
// world run faster than real time) while the world steps, and kPausedViewFrequency times per
// wall second while it stands (a model moved by set_model_state moves in the view).
// What the world gives is taken under its lock (collect: copies only); the messages are made
// and published without it.
#pragma once

#include <chrono>
#include <cstdint>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gazebo_msgs/ModelStates.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <visualization_msgs/MarkerArray.h>

#include <onedof_sim/world.h>

namespace onedof_sim {

constexpr double kViewFrequency = 10.0;        // Hz of sim time
constexpr double kMaxViewFrequency = 20.0;     // Hz of wall time
constexpr double kPausedViewFrequency = 5.0;   // Hz of wall time

// The markers of each view (ns: the model's name; frame `world`).
// A collision shape, grey and translucent; a plane a faint square.
visualization_msgs::Marker collisionMarker(const CollisionShape& shape, int id);
// A visual in its material's diffuse colour (render/materials.h: Gazebo's named materials and
// the colours given); a mesh without a material in its file's own materials. False, the reason
// in *why, for a visual that cannot be drawn (a mesh file not found); *why also says when a
// drawn visual's material is not known (drawn white).
bool visualMarker(const VisualShape& visual, int id, visualization_msgs::Marker* marker,
                  std::string* why);
// A joint's origin (id) and, for a moving joint, its axis as an arrow (id + 1).
std::vector<visualization_msgs::Marker> jointMarkers(const JointAxis& joint, int id);
// A link's centre of mass: a sphere of lead of its mass.
visualization_msgs::Marker comMarker(const LinkMass& mass, int id);
// A link's box of the same mass and inertia, on its principal axes.
visualization_msgs::Marker inertiaMarker(const LinkMass& mass, int id);
// The contacts' points and their normals (two markers; none without a point).
std::vector<visualization_msgs::Marker> contactMarkers(const std::vector<Contact>& contacts);

class ViewMarkers {
 public:
  // What the views due at one moment need of the world.
  struct Facts {
    bool visuals = false, collisions = false, joints = false, coms = false, inertias = false,
         contacts = false, model_states = false, clock = false;
    bool taken = false;  // collect took them: publish has something to send
    std::vector<VisualShape> visual_shapes;
    std::vector<CollisionShape> collision_shapes;
    std::vector<JointAxis> joint_axes;
    std::vector<LinkMass> link_masses;  // for coms and inertias
    std::vector<Contact> contact_list;
    gazebo_msgs::ModelStates model_state_list;
    int64_t time_ns = 0;  // the world's time when taken
    bool any() const {
      return visuals || collisions || joints || coms || inertias || contacts || model_states ||
             clock;
    }
  };

  // Advertises every view's topic under nh, or takes them all down.
  void advertise(ros::NodeHandle& nh);
  void shutdown();
  bool advertised() const { return advertised_; }
  // World locked, after a step (stepped) or while the world stands: when the views are due (by
  // the world's time, or by the wall clock while it stands), marks in *out the views someone
  // subscribes to and takes what they need. Subscribers are asked only then, not at every step.
  void collect(const World& world, bool stepped, Facts* out);
  // Unlocked: the wanted views' messages, published.
  void publish(const Facts& facts);

 private:
  // One view's topic and the markers it last published, for the DELETEs of those gone (a
  // deleted model's): rviz keeps a marker until told.
  struct View {
    ros::Publisher pub;
    std::set<std::pair<std::string, int32_t>> shown;
    void publish(std::vector<visualization_msgs::Marker> markers);
  };
  View visuals_, collisions_, joints_, coms_, inertias_, contacts_;
  ros::Publisher model_states_, clock_;
  bool advertised_ = false;
  int64_t last_ns_ = -1;  // sim time of the last views taken
  std::chrono::steady_clock::time_point last_wall_;
  std::set<std::string> reported_;  // visuals said once not to be drawn, and why
};

}  // namespace onedof_sim
