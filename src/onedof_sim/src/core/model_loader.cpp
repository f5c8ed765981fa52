// URDF (urdfdom) and SDF (libsdformat 12) to ModelDescription.
#include <console_bridge/console.h>
#include <cmath>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <limits>
#include <ignition/math/Pose3.hh>
#include <map>
#include <mutex>
#include <sdf/sdf.hh>
#include <set>
#include <sstream>

#include "mesh_loader.h"
#include "model_description.h"
#include "onedof_sim/pose_math.h"
#include "sdf_parsing.h"
#include "urdf_extensions.h"
#include "visual_loader.h"

namespace onedof_sim {
namespace core {
namespace {

// Gazebo reads a negative coefficient as unbounded friction (ODE's dInfinity): the largest float,
// as an infinite one is.
double frictionCoefficient(double mu) {
  return mu < 0 || std::isinf(mu) ? double(std::numeric_limits<float>::max()) : mu;
}

// urdfdom reports why it rejects a file only through console_bridge; this collects those lines so
// that the spawn status can carry the parser's reason. It also drops an element it cannot parse
// (a box of size "nan 1 1") with an error line and returns the rest of the model, so an error
// line is a refusal even when a model came back.
class CapturedParserErrors : public console_bridge::OutputHandler {
 public:
  CapturedParserErrors() { console_bridge::useOutputHandler(this); }
  ~CapturedParserErrors() override { console_bridge::restorePreviousOutputHandler(); }
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) lines_ += (lines_.empty() ? "" : "; ") + text;
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) has_errors_ = true;
  }
  const std::string& text() const { return lines_; }
  bool hasErrors() const { return has_errors_; }

 private:
  std::string lines_;
  bool has_errors_ = false;
};

Pose toPose(const urdf::Pose& p) {
  return {{p.position.x, p.position.y, p.position.z},
          normalized({p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z})};
}

// Beside the one for libsdformat's poses (sdf_parsing.h).
using core::toPose;

Vec3 unit(const Vec3& v) { return (1.0 / norm(v)) * v; }

std::string collisionName(const std::string& given, const std::string& link, size_t index) {
  // Gazebo's URDF conversion names unnamed collisions this way; clients see them as geom names.
  if (!given.empty()) return given;
  return link + "_collision" + (index == 0 ? "" : "_" + std::to_string(index));
}

std::string formatNumber(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

bool withinPosition(const Vec3& v) {
  return std::abs(v.x) <= kMaxPosition && std::abs(v.y) <= kMaxPosition &&
         std::abs(v.z) <= kMaxPosition;
}

// The Limits (model_description.h) on what a model file gives; finish() has checked finiteness
// of the joints, checkShape that of the shapes.
Status checkLimits(const ModelDescription& model) {
  if (model.links.size() > kMaxModelLinks)
    return rejected("the model has " + std::to_string(model.links.size()) + " links; at most " +
                    std::to_string(kMaxModelLinks) + " are accepted");
  const std::string position_range = " beyond " + formatNumber(kMaxPosition) + " m";
  for (const LinkDescription& link : model.links) {
    const std::string what = "link '" + link.name + "'";
    if (!withinPosition(link.pose.position) || !withinPosition(link.com.position))
      return rejected(what + " lies" + position_range + " of the model origin");
    const double moments[] = {link.ixx, link.ixy, link.ixz, link.iyy, link.iyz, link.izz};
    for (double moment : moments)
      if (std::isfinite(moment) && std::abs(moment) > kMaxMoment)
        return rejected(what + " has an inertia component of " + formatNumber(moment) +
                        " kg m^2; at most " + formatNumber(kMaxMoment) + " is accepted");
    if (link.has_inertial && std::isfinite(link.mass) && link.mass != 0 &&
        (std::abs(link.mass) < kMinMass || link.mass > kMaxMass))
      return rejected(what + " has a mass of " + formatNumber(link.mass) +
                      " kg; a mass must be 0 or in [" + formatNumber(kMinMass) + ", " +
                      formatNumber(kMaxMass) + "] kg");
    for (const CollisionDescription& collision : link.collisions) {
      const Vec3& size = collision.size;
      if (!withinPosition(collision.pose.position))
        return rejected(what + ": collision '" + collision.name + "' lies" + position_range);
      const TriangleMesh* mesh = collision.mesh.get();
      // A plane is unbounded whatever its <size>, which only a visual shows.
      const bool too_large =
          mesh ? std::max({std::abs(mesh->min.x), std::abs(mesh->min.y), std::abs(mesh->min.z),
                           std::abs(mesh->max.x), std::abs(mesh->max.y),
                           std::abs(mesh->max.z)}) > kMaxShapeSize / 2
               : collision.shape != GeometryShape::Plane &&
                     std::max({size.x, size.y, size.z}) > kMaxShapeSize;
      if (too_large)
        return rejected(what + ": collision '" + collision.name + "' is larger than " +
                        formatNumber(kMaxShapeSize) + " m" +
                        (mesh ? " (a mesh: more than half of it from its origin)" : ""));
    }
  }
  for (const JointDescription& joint : model.joints) {
    const std::string what = "joint '" + joint.name + "'";
    if (!withinPosition(joint.anchor)) return rejected(what + " lies" + position_range);
    if (!(std::abs(joint.damping) <= kMaxJointDamping))
      return rejected(what + " has a damping of " + formatNumber(joint.damping) + "; at most " +
                      formatNumber(kMaxJointDamping) + " is accepted");
    if (!(std::abs(joint.friction) <= kMaxJointFriction))
      return rejected(what + " has a friction of " + formatNumber(joint.friction) +
                      "; at most " + formatNumber(kMaxJointFriction) + " is accepted");
  }
  return {};
}

// Checks the kinematic tree shared by both formats and orders links parents first, which the
// world relies on when it walks the tree.
Status finish(ModelDescription* model) {
  Status limits = checkLimits(*model);
  if (!limits.ok()) return limits;
  std::map<std::string, size_t> link_index;
  for (size_t i = 0; i < model->links.size(); ++i) {
    const std::string& name = model->links[i].name;
    if (name == kWorldLink) return rejected("a model link may not be called 'world'");
    if (!link_index.emplace(name, i).second) return rejected("duplicate link '" + name + "'");
  }
  if (model->links.empty()) return rejected("the model has no link");
  std::map<std::string, const JointDescription*> parent_joint;
  std::set<std::string> joint_names;
  for (const JointDescription& joint : model->joints) {
    if (!joint_names.insert(joint.name).second)
      return rejected("duplicate joint '" + joint.name + "'");
    if (!link_index.count(joint.child))
      return rejected("joint '" + joint.name + "' has unknown child link '" + joint.child + "'");
    if (joint.parent == joint.child)
      return rejected("joint '" + joint.name + "' has link '" + joint.child +
                      "' as both its parent and its child");
    if (joint.parent != kWorldLink && !link_index.count(joint.parent))
      return rejected("joint '" + joint.name + "' has unknown parent link '" + joint.parent +
                      "'");
    if (!parent_joint.emplace(joint.child, &joint).second)
      return rejected("link '" + joint.child + "' is the child of more than one joint");
    if (!isFinite(joint.anchor) || !isFinite(joint.axis) || norm(joint.axis) < 1e-9)
      return rejected("joint '" + joint.name + "' has an invalid axis");
  }
  std::vector<LinkDescription> ordered;
  std::set<std::string> placed;
  std::function<bool(const std::string&, int)> place = [&](const std::string& name, int depth) {
    if (placed.count(name) || name == kWorldLink) return true;
    if (depth > static_cast<int>(model->links.size())) return false;  // a loop of joints
    auto parent = parent_joint.find(name);
    if (parent != parent_joint.end() && !place(parent->second->parent, depth + 1)) return false;
    ordered.push_back(model->links[link_index.at(name)]);
    placed.insert(name);
    return true;
  };
  for (const LinkDescription& link : model->links)
    if (!place(link.name, 0)) return rejected("the joints form a loop");
  model->links = std::move(ordered);
  if (!link_index.count(model->canonical_link))
    return rejected("unknown canonical link '" + model->canonical_link + "'");
  return {};
}

std::string joinedPath(const std::vector<std::string>& folders) {
  std::string text;
  for (const std::string& folder : folders) text += (text.empty() ? "" : ", ") + folder;
  return text.empty() ? "(empty)" : text;
}

// A mesh collision: the file its URI names (resolveMeshUri), read and scaled. A mesh found
// nowhere leaves the collision out, as Gazebo leaves out a mesh it cannot load: *left_out says
// why, and *c is not made.
Status meshCollision(const std::string& uri, const Vec3& scale, const std::string& relative_to,
                     const std::vector<std::string>& model_path, MeshReader* meshes,
                     const std::string& link, CollisionDescription* c, std::string* left_out) {
  const std::string where =
      "link '" + link + "': collision '" + c->name + "' is the mesh '" + uri + "'";
  if (!isFinite(scale) || scale.x == 0 || scale.y == 0 || scale.z == 0)
    return rejected(where + " with a zero or non-finite scale");
  const std::string file = resolveMeshUri(uri, model_path, relative_to);
  if (file.empty()) {
    *left_out = where + ", which is not found or not readable (model:// and package:// URIs are "
                "looked up within " + joinedPath(model_path) + ")";
    return {};
  }
  c->shape = GeometryShape::Mesh;
  c->size = scale;
  Status status = meshes->read(file, scale, &c->mesh);
  if (!status.ok()) return rejected(where + ": " + status.subject);
  return {};
}

// Adds the collision to link, or its reason to *left_out (a mesh found nowhere).
Status addUrdfCollision(const urdf::Collision& collision, size_t index,
                        const std::vector<std::string>& model_path, MeshReader* meshes,
                        LinkDescription* link, std::vector<std::string>* left_out) {
  CollisionDescription out;
  out.name = collisionName(collision.name, link->name, index);
  out.pose = toPose(collision.origin);
  if (!collision.geometry) return rejected("collision of link '" + link->name + "' has no geometry");
  switch (collision.geometry->type) {
    case urdf::Geometry::BOX: {
      const auto& box = static_cast<const urdf::Box&>(*collision.geometry);
      out.shape = GeometryShape::Box;
      out.size = {box.dim.x, box.dim.y, box.dim.z};
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(*collision.geometry);
      out.shape = GeometryShape::Cylinder;
      out.size = {cylinder.radius, 0, cylinder.length};
      break;
    }
    case urdf::Geometry::SPHERE: {
      out.shape = GeometryShape::Sphere;
      out.size = {static_cast<const urdf::Sphere&>(*collision.geometry).radius, 0, 0};
      break;
    }
    case urdf::Geometry::MESH: {
      const auto& mesh = static_cast<const urdf::Mesh&>(*collision.geometry);
      std::string missing;
      Status status = meshCollision(mesh.filename, {mesh.scale.x, mesh.scale.y, mesh.scale.z}, "",
                                    model_path, meshes, link->name, &out, &missing);
      if (!status.ok()) return status;
      if (!missing.empty()) {
        left_out->push_back(missing);
        return {};
      }
      break;
    }
    default:
      return rejected("link '" + link->name +
                      "': only box, cylinder, sphere and mesh collisions are supported");
  }
  link->collisions.push_back(out);
  return {};
}

Status checkShape(const CollisionDescription& collision, const std::string& link) {
  const Vec3& s = collision.size;
  const bool ok = collision.shape == GeometryShape::Box ? (s.x > 0 && s.y > 0 && s.z > 0)
                  : collision.shape == GeometryShape::Cylinder ? (s.x > 0 && s.z > 0)
                  : collision.shape == GeometryShape::Mesh     ? collision.mesh != nullptr
                  : collision.shape == GeometryShape::Plane    ? (s.x >= 0 && s.y >= 0)
                                                               : s.x > 0;
  if (ok && isFinite(s) && isFinite(collision.pose)) return {};
  return rejected("link '" + link + "': collision '" + collision.name +
                  "' has a non-positive or non-finite size or pose");
}

Pose childPose(const Pose& parent_pose, const urdf::Joint& joint) {
  return compose(parent_pose, toPose(joint.parent_to_joint_origin_transform));
}

// Adds one URDF link (at its model-frame pose) and the joints to its children.
Status addUrdfLink(const urdf::Link& link, const Pose& pose,
                   const std::vector<std::string>& model_path,
                   const std::map<std::string, UrdfLinkExtension>& extensions,
                   MeshReader* meshes, ModelDescription* out) {
  if (link.name != kWorldLink) {
    LinkDescription desc;
    desc.name = link.name;
    desc.pose = pose;
    if (link.inertial) {
      const urdf::Inertial& inertial = *link.inertial;
      desc.has_inertial = true;
      desc.mass = inertial.mass;
      desc.com = toPose(inertial.origin);
      desc.ixx = inertial.ixx, desc.ixy = inertial.ixy, desc.ixz = inertial.ixz;
      desc.iyy = inertial.iyy, desc.iyz = inertial.iyz, desc.izz = inertial.izz;
    }
    // urdfdom keeps a lone <collision> only in `collision`, several in `collision_array`.
    std::vector<urdf::CollisionSharedPtr> collisions = link.collision_array;
    if (collisions.empty() && link.collision) collisions.push_back(link.collision);
    for (size_t i = 0; i < collisions.size(); ++i) {
      const size_t made = desc.collisions.size();
      Status status = addUrdfCollision(*collisions[i], i, model_path, meshes, &desc, &out->left_out);
      if (!status.ok()) return status;
      if (desc.collisions.size() == made) continue;
      status = checkShape(desc.collisions.back(), desc.name);
      if (!status.ok()) return status;
    }
    const auto extension = extensions.find(link.name);
    if (extension != extensions.end()) {
      for (CollisionDescription& collision : desc.collisions) {
        if (extension->second.mu1) collision.mu = frictionCoefficient(*extension->second.mu1);
        if (extension->second.mu2) collision.mu2 = frictionCoefficient(*extension->second.mu2);
      }
    }
    addUrdfVisuals(link, extension == extensions.end() ? "" : extension->second.material,
                   model_path, &desc);
    out->links.push_back(desc);
  }
  for (const urdf::JointSharedPtr& joint : link.child_joints) {
    JointDescription desc;
    desc.name = joint->name;
    desc.parent = link.name;
    desc.child = joint->child_link_name;
    switch (joint->type) {
      case urdf::Joint::REVOLUTE: desc.type = JointType::Revolute; break;
      case urdf::Joint::CONTINUOUS: desc.type = JointType::Continuous; break;
      case urdf::Joint::PRISMATIC: desc.type = JointType::Prismatic; break;
      case urdf::Joint::FIXED: desc.type = JointType::Fixed; break;
      default:
        return rejected("joint '" + joint->name +
                        "': only revolute, continuous, prismatic and fixed joints are supported");
    }
    // The URDF joint frame is the child link frame.
    const Pose child_pose = childPose(pose, *joint);
    desc.anchor = child_pose.position;
    const Vec3 axis{joint->axis.x, joint->axis.y, joint->axis.z};
    if (desc.type != JointType::Fixed) {
      if (!(norm(axis) > 1e-9)) return rejected("joint '" + joint->name + "' has a zero axis");
      desc.axis = unit(rotate(child_pose.orientation, axis));
    }
    if (joint->limits) {
      if (desc.type == JointType::Revolute || desc.type == JointType::Prismatic) {
        desc.has_limits = true;
        desc.lower = joint->limits->lower;
        desc.upper = joint->limits->upper;
      }
      // urdfdom reads a missing effort as 0; a joint that can take no effort at all is not what
      // anyone writes, so only a positive value limits.
      if (joint->limits->effort > 0) desc.effort_limit = joint->limits->effort;
    }
    if (joint->dynamics) {
      // urdfdom rejects <dynamics> with neither attribute and reads a missing one as 0, so damping
      // was declared if it is non-zero or if friction (the only alternative) is zero.
      desc.has_damping = joint->dynamics->damping != 0 || joint->dynamics->friction == 0;
      desc.damping = joint->dynamics->damping;
      desc.friction = joint->dynamics->friction;
    }
    out->joints.push_back(desc);
  }
  return {};
}

}  // namespace

Status parseUrdf(const std::string& xml, const std::vector<std::string>& model_path,
                 ModelDescription* out) {
  urdf::ModelInterfaceSharedPtr urdf;
  std::string parser_errors;
  bool parser_has_errors = false;
  {
    const std::lock_guard<std::mutex> one_parser(parserMutex());
    CapturedParserErrors errors;
    urdf = urdf::parseURDF(xml);
    parser_errors = errors.text();
    parser_has_errors = errors.hasErrors();
  }
  if (!urdf) return rejected("invalid URDF: " + (parser_errors.empty() ? "parse failed" : parser_errors));
  if (parser_has_errors) return rejected("invalid URDF: " + parser_errors);
  // Before the tree is walked: a walk is as deep as the tree.
  const size_t links = urdf->links_.size() - urdf->links_.count(kWorldLink);
  if (links > kMaxModelLinks)
    return rejected("the model has " + std::to_string(links) + " links; at most " +
                    std::to_string(kMaxModelLinks) + " are accepted");
  // urdfdom keeps a joint whose parent is its child, and its link, out of the tree it builds; the
  // walk from the root would drop both without a word.
  for (const auto& [name, joint] : urdf->joints_)
    if (joint->parent_link_name == joint->child_link_name)
      return rejected("joint '" + name + "' has link '" + joint->child_link_name +
                      "' as both its parent and its child");
  ModelDescription model;
  MeshReader meshes;
  std::map<std::string, UrdfLinkExtension> extensions;
  Status read = urdfLinkExtensions(xml, &extensions);
  if (!read.ok()) return read;
  std::function<Status(const urdf::Link&, const Pose&)> visit = [&](const urdf::Link& link,
                                                                     const Pose& pose) {
    Status status = addUrdfLink(link, pose, model_path, extensions, &meshes, &model);
    if (!status.ok()) return status;
    for (const urdf::JointSharedPtr& joint : link.child_joints) {
      const urdf::LinkConstSharedPtr child = urdf->getLink(joint->child_link_name);
      status = visit(*child, childPose(pose, *joint));
      if (!status.ok()) return status;
    }
    return Status();
  };
  Status status = visit(*urdf->getRoot(), Pose());
  if (!status.ok()) return status;
  if (model.links.empty()) return rejected("the URDF has no link besides 'world'");
  // Every link hangs from the root, or it was dropped (a loop of joints: urdfdom finds no root).
  if (model.links.size() != links)
    return rejected("the URDF's links do not form one tree from its root link");
  model.canonical_link = model.links.front().name;
  status = finish(&model);
  if (!status.ok()) return status;
  *out = std::move(model);
  return {};
}

// Models are prepared on any thread (World::prepare), so the parsers run one at a time: urdfdom
// reports through console_bridge's one process-wide handler (CapturedParserErrors swaps it), and
// libsdformat 12 does not say it may be used from several threads at once.
std::mutex& parserMutex() {
  static std::mutex parsers;
  return parsers;
}

Pose toPose(const ignition::math::Pose3d& p) {
  return {{p.Pos().X(), p.Pos().Y(), p.Pos().Z()},
          normalized({p.Rot().W(), p.Rot().X(), p.Rot().Y(), p.Rot().Z()})};
}

std::string joinErrors(const sdf::Errors& errors) {
  std::ostringstream text;
  for (size_t i = 0; i < errors.size(); ++i) text << (i ? "; " : "") << errors[i].Message();
  return text.str();
}

namespace {

// libsdformat 12 has no accessor for <surface><friction><ode>, so read the element.
void readSdfFriction(const sdf::Collision& collision, CollisionDescription* out) {
  sdf::ElementPtr element = collision.Element();
  for (const char* name : {"surface", "friction", "ode"}) {
    if (!element || !element->HasElement(name)) return;
    element = element->GetElement(name);
  }
  if (element->HasElement("mu")) out->mu = frictionCoefficient(element->Get<double>("mu"));
  if (element->HasElement("mu2")) out->mu2 = frictionCoefficient(element->Get<double>("mu2"));
}

// A <plane>: the plane z = 0 of the collision's frame, its <normal> turned into that frame's z;
// its <size> only says how much of it a visual shows.
void planeCollision(const sdf::Plane& plane, CollisionDescription* c) {
  const ignition::math::Vector3d& normal = plane.Normal();
  c->shape = GeometryShape::Plane;
  c->size = {plane.Size().X(), plane.Size().Y(), 0};
  c->pose.orientation =
      multiply(c->pose.orientation, zTo({normal.X(), normal.Y(), normal.Z()}));
}

Status addSdfLink(const sdf::Link& link, const Pose& model_pose, const std::string& prefix,
                  const std::vector<std::string>& model_path, MeshReader* meshes,
                  ModelDescription* out) {
  LinkDescription desc;
  desc.name = prefix + link.Name();
  ignition::math::Pose3d pose;
  sdf::Errors errors = link.SemanticPose().Resolve(pose, "__model__");
  if (!errors.empty()) return rejected("link '" + desc.name + "': " + joinErrors(errors));
  desc.pose = compose(model_pose, toPose(pose));
  const ignition::math::Inertiald& inertial = link.Inertial();
  desc.has_inertial = true;
  desc.mass = inertial.MassMatrix().Mass();
  desc.com = toPose(inertial.Pose());
  desc.ixx = inertial.MassMatrix().Ixx(), desc.ixy = inertial.MassMatrix().Ixy();
  desc.ixz = inertial.MassMatrix().Ixz(), desc.iyy = inertial.MassMatrix().Iyy();
  desc.iyz = inertial.MassMatrix().Iyz(), desc.izz = inertial.MassMatrix().Izz();
  if (link.Element() && link.Element()->HasElement("gravity"))
    desc.gravity = link.Element()->Get<bool>("gravity");
  for (uint64_t i = 0; i < link.CollisionCount(); ++i) {
    const sdf::Collision& collision = *link.CollisionByIndex(i);
    CollisionDescription c;
    c.name = collision.Name();
    errors = collision.SemanticPose().Resolve(pose, link.Name());
    if (!errors.empty()) return rejected("collision '" + c.name + "': " + joinErrors(errors));
    c.pose = toPose(pose);
    const sdf::Geometry& geometry = *collision.Geom();
    if (geometry.Type() == sdf::GeometryType::BOX) {
      const auto& size = geometry.BoxShape()->Size();
      c.shape = GeometryShape::Box;
      c.size = {size.X(), size.Y(), size.Z()};
    } else if (geometry.Type() == sdf::GeometryType::CYLINDER) {
      c.shape = GeometryShape::Cylinder;
      c.size = {geometry.CylinderShape()->Radius(), 0, geometry.CylinderShape()->Length()};
    } else if (geometry.Type() == sdf::GeometryType::SPHERE) {
      c.shape = GeometryShape::Sphere;
      c.size = {geometry.SphereShape()->Radius(), 0, 0};
    } else if (geometry.Type() == sdf::GeometryType::MESH) {
      const sdf::Mesh& mesh = *geometry.MeshShape();
      const ignition::math::Vector3d& scale = mesh.Scale();
      const std::string folder =
          mesh.FilePath().empty() ? "" : std::filesystem::path(mesh.FilePath()).parent_path();
      std::string missing;
      Status status = meshCollision(mesh.Uri(), {scale.X(), scale.Y(), scale.Z()}, folder,
                                    model_path, meshes, desc.name, &c, &missing);
      if (!status.ok()) return status;
      if (!missing.empty()) {
        out->left_out.push_back(missing);
        continue;
      }
    } else if (geometry.Type() == sdf::GeometryType::PLANE) {
      planeCollision(*geometry.PlaneShape(), &c);
    } else {
      return rejected("link '" + desc.name +
                      "': only box, cylinder, sphere, plane and mesh collisions are supported");
    }
    readSdfFriction(collision, &c);
    Status status = checkShape(c, desc.name);
    if (!status.ok()) return status;
    desc.collisions.push_back(c);
  }
  std::string visual_error;
  if (!addSdfVisuals(link, model_path, &desc, &visual_error)) return rejected(visual_error);
  out->links.push_back(desc);
  return {};
}

// The joint's name as the file gives it: libsdformat 12 renames a joint that shares its name
// with a link ("door" to "door_joint"), where Gazebo keeps it.
std::string givenName(const sdf::Joint& joint) {
  const sdf::ElementPtr element = joint.Element();
  return element && element->HasAttribute("name") ? element->Get<std::string>("name")
                                                   : joint.Name();
}

Status addSdfJoint(const sdf::Joint& joint, const Pose& model_pose, const std::string& prefix,
                   ModelDescription* out) {
  JointDescription desc;
  desc.name = prefix + givenName(joint);
  switch (joint.Type()) {
    case sdf::JointType::REVOLUTE: desc.type = JointType::Revolute; break;
    case sdf::JointType::CONTINUOUS: desc.type = JointType::Continuous; break;
    case sdf::JointType::PRISMATIC: desc.type = JointType::Prismatic; break;
    case sdf::JointType::FIXED: desc.type = JointType::Fixed; break;
    default:
      return rejected("joint '" + desc.name +
                      "': only revolute, continuous, prismatic and fixed joints are supported");
  }
  const std::string& parent = joint.ParentLinkName();
  desc.parent = parent == kWorldLink ? parent : prefix + parent;
  desc.child = prefix + joint.ChildLinkName();
  ignition::math::Pose3d pose;
  sdf::Errors errors = joint.SemanticPose().Resolve(pose, "__model__");
  if (!errors.empty()) return rejected("joint '" + desc.name + "': " + joinErrors(errors));
  desc.anchor = transformPoint(model_pose, toPose(pose).position);
  if (const sdf::JointAxis* axis = joint.Axis(0)) {
    ignition::math::Vector3d xyz;
    errors = axis->ResolveXyz(xyz, "__model__");
    if (!errors.empty()) return rejected("joint '" + desc.name + "': " + joinErrors(errors));
    const Vec3 model_axis = rotate(model_pose.orientation, {xyz.X(), xyz.Y(), xyz.Z()});
    if (!(norm(model_axis) > 1e-9)) return rejected("joint '" + desc.name + "' has a zero axis");
    desc.axis = unit(model_axis);
    // SDF's "no limit" defaults are +-1e16.
    if (desc.type != JointType::Continuous && std::abs(axis->Lower()) < 1e15 &&
        std::abs(axis->Upper()) < 1e15) {
      desc.has_limits = true;
      desc.lower = axis->Lower();
      desc.upper = axis->Upper();
    }
    if (axis->Effort() > 0) desc.effort_limit = axis->Effort();
    sdf::ElementPtr element = axis->Element();
    desc.has_damping = element && element->HasElement("dynamics") &&
                       element->GetElement("dynamics")->HasElement("damping");
    desc.damping = axis->Damping();
    desc.friction = axis->Friction();
  } else if (desc.type != JointType::Fixed) {
    return rejected("joint '" + desc.name + "' has no <axis>");
  }
  out->joints.push_back(desc);
  return {};
}

// Nested models become links and joints named "nested::name" in one flat model.
Status addSdfModel(const sdf::Model& model, const Pose& model_pose, const std::string& prefix,
                   const std::vector<std::string>& model_path, MeshReader* meshes,
                   ModelDescription* out) {
  for (uint64_t i = 0; i < model.LinkCount(); ++i) {
    Status status = addSdfLink(*model.LinkByIndex(i), model_pose, prefix, model_path, meshes, out);
    if (!status.ok()) return status;
  }
  for (uint64_t i = 0; i < model.JointCount(); ++i) {
    Status status = addSdfJoint(*model.JointByIndex(i), model_pose, prefix, out);
    if (!status.ok()) return status;
  }
  for (uint64_t i = 0; i < model.ModelCount(); ++i) {
    const sdf::Model& nested = *model.ModelByIndex(i);
    ignition::math::Pose3d pose;
    sdf::Errors errors = nested.SemanticPose().Resolve(pose, "__model__");
    if (!errors.empty()) return rejected("model '" + nested.Name() + "': " + joinErrors(errors));
    Status status =
        addSdfModel(nested, compose(model_pose, toPose(pose)), prefix + nested.Name() + "::",
                    model_path, meshes, out);
    if (!status.ok()) return status;
  }
  return {};
}

}  // namespace

// libsdformat looks model://NAME up as FOLDER/NAME in each folder given; a miss is only recorded
// here, so that the refusal can name the folders searched.
sdf::ParserConfig modelPathConfig(const std::vector<std::string>& model_path,
                                  std::vector<std::string>* missing) {
  sdf::ParserConfig config;
  for (const std::string& folder : model_path) config.AddURIPath("model://", folder);
  config.SetFindCallback([missing](const std::string& uri) {
    missing->push_back(uri);
    return std::string();
  });
  return config;
}

// libsdformat converts older SDF versions up to its own, but reads a newer one as its own with
// only a line on stderr ("Unable to convert from SDF version 99"): refused here, naming both.
Status checkSdfVersion(const sdf::Root& root) {
  const std::string given = root.Element() ? root.Element()->OriginalVersion() : "";
  const auto number = [](const std::string& text, int* major, int* minor) {
    std::istringstream in(text);
    char dot = 0;
    return static_cast<bool>(in >> *major >> dot >> *minor) && dot == '.' && in.peek() == EOF;
  };
  int major = 0, minor = 0, max_major = 0, max_minor = 0;
  if (!number(sdf::SDF::Version(), &max_major, &max_minor)) return {};
  if (number(given, &major, &minor) && major >= 1 &&
      (major < max_major || (major == max_major && minor <= max_minor)))
    return {};
  return rejected("invalid SDF: version '" + given + "' is not one this libsdformat reads (1.0 to " +
                  sdf::SDF::Version() + ")");
}

Status parseSdf(const std::string& xml, const std::vector<std::string>& model_path,
                ModelDescription* out) {
  SdfDocument document;
  const std::lock_guard<std::mutex> one_parser(parserMutex());
  readSdfDocument(xml, SdfSource::String, model_path, &document);
  if (document.includes.code == IncludeCheck::Code::Cycle)
    return rejected("invalid SDF: its <include>s include themselves: " + document.includes.subject);
  if (document.includes.code == IncludeCheck::Code::TooMany)
    return rejected("invalid SDF: its <include>s, nested ones counted each time, place " +
                    std::string(document.includes.at_least ? "at least " : "") +
                    std::to_string(document.includes.count) + " models; at most " +
                    std::to_string(kMaxIncludedModels) + " are accepted");
  if (document.includes.code == IncludeCheck::Code::NotFound)
    document.missing.push_back(document.includes.subject);
  if (!document.missing.empty())
    return rejected(document.missing.front() + " is not in the model path or is no readable "
                    "regular file (" + joinedPath(model_path) + ")");
  if (!document.error.empty()) return rejected("invalid SDF: " + document.error);
  const sdf::Root& root = document.root;
  const Status version = checkSdfVersion(root);
  if (!version.ok()) return version;
  // What gazebo_ros' spawn_model sends for -database: <world><include><uri>model://NAME, which
  // libsdformat has turned into the world's one model; its <pose> is the include's.
  const sdf::World* world = root.WorldCount() == 1 ? root.WorldByIndex(0) : nullptr;
  const sdf::Model* model = root.Model();
  if (!model && world && world->ModelCount() == 1) model = world->ModelByIndex(0);
  if (!model)
    return rejected("invalid SDF: no <model> at the top level, nor one <world> with one "
                    "<include> or <model>");
  ModelDescription desc;
  const Status status = describeSdfModel(*model, model_path, &desc);
  if (!status.ok()) return status;
  desc.pose = toPose(model->RawPose());
  *out = std::move(desc);
  return {};
}

Status describeSdfModel(const sdf::Model& model, const std::vector<std::string>& model_path,
                        ModelDescription* out) {
  ModelDescription desc;
  desc.is_static = model.Static();
  MeshReader meshes;
  Status status = addSdfModel(model, Pose(), "", model_path, &meshes, &desc);
  if (!status.ok()) return status;
  const auto canonical = model.CanonicalLinkAndRelativeName();
  if (!canonical.first) return rejected("invalid SDF: the model has no link");
  desc.canonical_link = canonical.second;
  status = finish(&desc);
  if (!status.ok()) return status;
  *out = std::move(desc);
  return {};
}

}  // namespace core
}  // namespace onedof_sim
