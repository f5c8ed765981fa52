#include "view_markers.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <onedof_sim/pose_math.h>

#include "conversions.h"
#include "materials.h"

namespace onedof_sim {
namespace {

using visualization_msgs::Marker;

constexpr const char* kFrame = "world";
// A plane (the ground_plane model's): its visual drawn at most as large as the view's grid (Gazebo's
// ground is 100 m: the view would have no horizon), just below its surface so that the grid on it
// is not hidden. The collision view shows an unbounded plane as a smaller square, faint.
constexpr double kPlaneVisualMaxSize = 20.0;  // m
constexpr double kPlaneCollisionSize = 10.0;  // m
constexpr double kPlaneThickness = 0.002;  // m
// Joints: the axis as an arrow this long from the joint's origin, the origin as a small ball.
constexpr double kJointAxisLength = 0.2;   // m
constexpr double kJointOriginDiameter = 0.02;  // m
// A centre of mass is drawn as Gazebo draws it, a sphere of lead of the link's mass.
constexpr double kLeadDensity = 11340;  // kg/m^3
// Contacts: a ball at each point, its normal a line this long.
constexpr double kContactDiameter = 0.02;  // m
constexpr double kContactNormalLength = 0.1;  // m

Marker base(const std::string& ns, int id, int type) {
  Marker marker;
  marker.header.frame_id = kFrame;
  marker.ns = ns;
  marker.id = id;
  marker.type = type;
  marker.action = Marker::ADD;
  marker.pose.orientation.w = 1;
  marker.scale.x = marker.scale.y = marker.scale.z = 1;
  return marker;
}

std_msgs::ColorRGBA rgba(float r, float g, float b, float a) {
  std_msgs::ColorRGBA color;
  color.r = r, color.g = g, color.b = b, color.a = a;
  return color;
}

// A primitive's marker type and scale (sizes as CollisionShape and VisualShape give them).
// False for a plane or a mesh.
bool primitive(GeometryShape shape, const Vec3& size, Marker* marker) {
  switch (shape) {
    case GeometryShape::Box:
      marker->type = Marker::CUBE;
      marker->scale = toVector3(size);
      return true;
    case GeometryShape::Cylinder:
      marker->type = Marker::CYLINDER;
      marker->scale.x = marker->scale.y = 2 * size.x;
      marker->scale.z = size.z;
      return true;
    case GeometryShape::Sphere:
      marker->type = Marker::SPHERE;
      marker->scale.x = marker->scale.y = marker->scale.z = 2 * size.x;
      return true;
    case GeometryShape::Plane:
    case GeometryShape::Mesh:
      break;
  }
  return false;
}

// A plane (its normal the pose's z axis) as a thin square of side x by y, its top face just
// below the plane.
void planeMarker(const Pose& pose, double x, double y, Marker* marker) {
  marker->type = Marker::CUBE;
  marker->scale.x = x;
  marker->scale.y = y;
  marker->scale.z = kPlaneThickness;
  const Vec3 normal = rotate(pose.orientation, {0, 0, 1});
  marker->pose = toMsg({pose.position - kPlaneThickness * normal, pose.orientation});
}

// The colour rviz lights a visual with: its material's diffuse colour, as Gazebo resolves it
// (src/render/materials.h, the table the cameras draw with).
std_msgs::ColorRGBA visualColor(const VisualMaterial& material, bool* known) {
  const render::SurfaceColors colors = render::resolveMaterial(material, known);
  return rgba(colors.diffuse.r, colors.diffuse.g, colors.diffuse.b, colors.diffuse.a);
}

geometry_msgs::Point point(const Vec3& v) {
  geometry_msgs::Point p;
  p.x = v.x, p.y = v.y, p.z = v.z;
  return p;
}

}  // namespace

Marker collisionMarker(const CollisionShape& shape, int id) {
  Marker marker = base(shape.model, id, Marker::CUBE);
  marker.pose = toMsg(shape.pose);
  marker.color = rgba(0.6f, 0.6f, 0.6f, 0.8f);
  if (primitive(shape.shape, shape.size, &marker)) return marker;
  if (shape.shape == GeometryShape::Mesh) {
    marker.type = Marker::MESH_RESOURCE;
    marker.mesh_resource = "file://" + shape.mesh_file;
    marker.scale = toVector3(shape.size);
  } else {
    planeMarker(shape.pose, kPlaneCollisionSize, kPlaneCollisionSize, &marker);
    marker.color.a = 0.3f;
  }
  return marker;
}

bool visualMarker(const VisualShape& visual, int id, Marker* marker, std::string* why) {
  *marker = base(visual.model, id, Marker::CUBE);
  marker->pose = toMsg(visual.pose);
  bool known = true;
  marker->color = visualColor(visual.material, &known);
  if (!known) *why = "drawn white: its material '" + visual.material.script + "' is not known";
  if (primitive(visual.shape, visual.size, marker)) return true;
  if (visual.shape == GeometryShape::Plane) {
    planeMarker(visual.pose, std::min(visual.size.x, kPlaneVisualMaxSize),
                std::min(visual.size.y, kPlaneVisualMaxSize), marker);
    return true;
  }
  if (visual.mesh_file.empty()) {
    *why = "not drawn: its mesh '" + visual.mesh_uri + "' is not found";
    return false;
  }
  marker->type = Marker::MESH_RESOURCE;
  marker->mesh_resource = "file://" + visual.mesh_file;
  marker->scale = toVector3(visual.size);
  // A mesh without a material shows its own (a COLLADA file's colours), as Gazebo shows it:
  // rviz uses the embedded materials untinted when the marker's colour is all zero.
  const VisualMaterial& m = visual.material;
  if (m.script.empty() && !m.ambient && !m.diffuse && !m.emissive) {
    marker->mesh_use_embedded_materials = true;
    marker->color = rgba(0, 0, 0, 0);
  }
  return true;
}

// The joint's origin (every joint) and its axis (the moving ones), ids id and id + 1.
std::vector<Marker> jointMarkers(const JointAxis& joint, int id) {
  std::vector<Marker> markers;
  Marker origin = base(joint.model, id, Marker::SPHERE);
  origin.pose.position = point(joint.anchor);
  origin.scale.x = origin.scale.y = origin.scale.z = kJointOriginDiameter;
  origin.color = rgba(1, 1, 0, 1);
  markers.push_back(origin);
  if (joint.type == JointType::Fixed) return markers;
  Marker axis = base(joint.model, id + 1, Marker::ARROW);
  axis.points = {point(joint.anchor), point(joint.anchor + kJointAxisLength * joint.axis)};
  axis.scale.x = 0.01;  // shaft diameter
  axis.scale.y = 0.025;  // head diameter
  axis.scale.z = 0.04;  // head length
  axis.color = rgba(1, 1, 0, 1);
  markers.push_back(axis);
  return markers;
}

Marker comMarker(const LinkMass& mass, int id) {
  Marker marker = base(mass.model, id, Marker::SPHERE);
  marker.pose = toMsg(mass.inertial);
  const double diameter = 2 * std::cbrt(3 * mass.mass / (4 * M_PI * kLeadDensity));
  marker.scale.x = marker.scale.y = marker.scale.z = diameter;
  marker.color = rgba(0.1f, 0.1f, 0.1f, 1);
  return marker;
}

// The box of the link's mass whose inertia is the link's, on its principal axes: a box's moment
// about x is m (y^2 + z^2) / 12, so x = sqrt(6 (Iy + Iz - Ix) / m), and so on.
Marker inertiaMarker(const LinkMass& mass, int id) {
  Eigen::Matrix3d inertia;
  inertia << mass.ixx, mass.ixy, mass.ixz, mass.ixy, mass.iyy, mass.iyz, mass.ixz, mass.iyz,
      mass.izz;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(inertia);
  Eigen::Matrix3d axes = solver.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
  const Eigen::Vector3d moments = solver.eigenvalues();
  const Eigen::Quaterniond principal(axes);
  Marker marker = base(mass.model, id, Marker::CUBE);
  const Quat q = multiply(mass.inertial.orientation,
                          {principal.w(), principal.x(), principal.y(), principal.z()});
  marker.pose = toMsg({mass.inertial.position, normalized(q)});
  auto side = [&](int i) {
    const double sum = moments((i + 1) % 3) + moments((i + 2) % 3) - moments(i);
    return std::sqrt(std::max(0.0, 6 * sum / mass.mass));
  };
  marker.scale.x = side(0);
  marker.scale.y = side(1);
  marker.scale.z = side(2);
  marker.color = rgba(0.6f, 0.2f, 0.8f, 0.5f);
  return marker;
}

// All the points in one list, the normals in another (collision1's side: the direction that
// moves it out of collision2).
std::vector<Marker> contactMarkers(const std::vector<Contact>& contacts) {
  Marker points = base("contacts", 0, Marker::SPHERE_LIST);
  points.scale.x = points.scale.y = points.scale.z = kContactDiameter;
  points.color = rgba(0, 0, 1, 1);
  Marker normals = base("contacts", 1, Marker::LINE_LIST);
  normals.scale.x = 0.005;  // line width
  normals.color = rgba(0, 1, 0, 1);
  for (const Contact& contact : contacts)
    for (const ContactPoint& p : contact.points) {
      points.points.push_back(point(p.position));
      normals.points.push_back(point(p.position));
      normals.points.push_back(point(p.position + kContactNormalLength * p.normal));
    }
  if (points.points.empty()) return {};
  return {points, normals};
}

namespace {

// Marker ids counted within each model's namespace, so that a model's markers keep their ids
// when another model is deleted.
class IdsByModel {
 public:
  int next(const std::string& model) { return counts_[model]++; }

 private:
  std::map<std::string, int> counts_;
};

}  // namespace

void ViewMarkers::View::publish(std::vector<Marker> markers) {
  std::set<std::pair<std::string, int32_t>> now;
  for (const Marker& marker : markers) now.insert({marker.ns, marker.id});
  for (const auto& [ns, id] : shown) {
    if (now.count({ns, id})) continue;
    Marker gone = base(ns, id, Marker::CUBE);
    gone.action = Marker::DELETE;
    markers.push_back(gone);
  }
  shown = std::move(now);
  visualization_msgs::MarkerArray array;
  array.markers = std::move(markers);
  pub.publish(array);
}

void ViewMarkers::advertise(ros::NodeHandle& nh) {
  using visualization_msgs::MarkerArray;
  const std::pair<View*, const char*> topics[] = {
      {&visuals_, "visual_markers"}, {&collisions_, "collision_markers"},
      {&joints_, "joint_markers"},   {&coms_, "com_markers"},
      {&inertias_, "inertia_markers"}, {&contacts_, "contact_markers"}};
  for (const auto& [view, topic] : topics) {
    view->pub = nh.advertise<MarkerArray>(topic, 1);
    view->shown.clear();
  }
  model_states_ = nh.advertise<gazebo_msgs::ModelStates>("view_model_states", 1);
  clock_ = nh.advertise<rosgraph_msgs::Clock>("view_clock", 1, true);
  advertised_ = true;
  last_ns_ = -1;  // due at once
  last_wall_ = {};
}

void ViewMarkers::shutdown() {
  for (View* view : {&visuals_, &collisions_, &joints_, &coms_, &inertias_, &contacts_}) {
    view->pub.shutdown();
    view->shown.clear();
  }
  model_states_.shutdown();
  clock_.shutdown();
  advertised_ = false;
}

void ViewMarkers::collect(const World& world, bool stepped, Facts* out) {
  *out = Facts();
  if (!advertised_) return;
  const int64_t time_ns = world.timeNs();
  const auto now = std::chrono::steady_clock::now();
  const auto since = std::chrono::duration<double>(now - last_wall_).count();
  const bool due = stepped ? last_ns_ < 0 || time_ns < last_ns_ ||
                                 (double(time_ns - last_ns_) >= 1e9 / kViewFrequency &&
                                  since >= 1 / kMaxViewFrequency)
                           : since >= 1 / kPausedViewFrequency;
  if (!due) return;
  out->visuals = visuals_.pub.getNumSubscribers() > 0;
  out->collisions = collisions_.pub.getNumSubscribers() > 0;
  out->joints = joints_.pub.getNumSubscribers() > 0;
  out->coms = coms_.pub.getNumSubscribers() > 0;
  out->inertias = inertias_.pub.getNumSubscribers() > 0;
  out->contacts = contacts_.pub.getNumSubscribers() > 0;
  out->model_states = model_states_.getNumSubscribers() > 0;
  out->clock = clock_.getNumSubscribers() > 0;
  if (!out->any()) return;  // no view open: nothing to look at
  last_ns_ = time_ns;
  last_wall_ = now;
  out->taken = true;
  out->time_ns = time_ns;
  if (out->visuals) out->visual_shapes = world.visualShapes();
  if (out->collisions) out->collision_shapes = world.collisionShapes();
  if (out->joints) out->joint_axes = world.jointAxes();
  if (out->coms || out->inertias) out->link_masses = world.linkMasses();
  if (out->contacts) out->contact_list = world.allContacts();
  if (out->model_states) out->model_state_list = modelStatesOf(world);
}

void ViewMarkers::publish(const Facts& facts) {
  if (!facts.taken) return;
  if (facts.visuals) {
    std::vector<Marker> markers;
    IdsByModel ids;
    for (const VisualShape& visual : facts.visual_shapes) {
      Marker marker;
      std::string why;
      if (visualMarker(visual, ids.next(visual.model), &marker, &why)) markers.push_back(marker);
      const std::string name = visual.model + "::" + visual.link + "::" + visual.name;
      if (!why.empty() && reported_.insert(name + why).second)
        ROS_WARN_STREAM("visual_markers: visual '" << name << "' " << why);
    }
    visuals_.publish(std::move(markers));
  }
  if (facts.collisions) {
    std::vector<Marker> markers;
    IdsByModel ids;
    for (const CollisionShape& shape : facts.collision_shapes)
      markers.push_back(collisionMarker(shape, ids.next(shape.model)));
    collisions_.publish(std::move(markers));
  }
  if (facts.joints) {
    std::vector<Marker> markers;
    IdsByModel ids;
    for (const JointAxis& joint : facts.joint_axes)
      for (Marker& marker : jointMarkers(joint, 2 * ids.next(joint.model)))
        markers.push_back(std::move(marker));
    joints_.publish(std::move(markers));
  }
  if (facts.coms || facts.inertias) {
    std::vector<Marker> coms, inertias;
    IdsByModel ids;
    for (const LinkMass& mass : facts.link_masses) {
      const int id = ids.next(mass.model);
      coms.push_back(comMarker(mass, id));
      inertias.push_back(inertiaMarker(mass, id));
    }
    if (facts.coms) coms_.publish(std::move(coms));
    if (facts.inertias) inertias_.publish(std::move(inertias));
  }
  if (facts.contacts) contacts_.publish(contactMarkers(facts.contact_list));
  if (facts.model_states) model_states_.publish(facts.model_state_list);
  if (facts.clock) {
    rosgraph_msgs::Clock clock;
    clock.clock.fromNSec(uint64_t(facts.time_ns));
    clock_.publish(clock);
  }
}

}  // namespace onedof_sim
