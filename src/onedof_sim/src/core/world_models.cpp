// Building a model (its link and joint records, its bodies and the engine's spec) and placing it
// at joint positions by forward kinematics, always through the zero configuration.
#include <map>
#include <sstream>
#include <stdexcept>

#include "world_impl.h"

namespace onedof_sim {

using namespace core;

namespace {

// A rigid motion of the model frame for a joint at position q: a rotation about the axis through
// the anchor, or a translation along the axis.
Pose jointMotion(const JointDescription& joint, double q) {
  switch (joint.type) {
    case JointType::Revolute:
    case JointType::Continuous: {
      const Quat r = axisAngle(joint.axis, q);
      return {joint.anchor - rotate(r, joint.anchor), r};
    }
    case JointType::Prismatic: return {q * joint.axis, Quat()};
    case JointType::Fixed: break;
  }
  return Pose();
}

}  // namespace

namespace core {

ShapeSpec shapeSpec(const CollisionDescription& collision) {
  return {collision.shape, collision.size, collision.pose, collision.mu, collision.mu2,
          collision.mesh};
}

bool isAnchored(const LinkRecord& link, const CollisionDescription& collision) {
  return link.body < 0 || collision.shape == GeometryShape::Plane;
}

const LinkRecord& referenceLink(const ModelRecord& model, int body) {
  for (const LinkRecord& link : model.links)
    if (link.body == body && link.sets_body_pose) return link;
  throw std::logic_error("body without a reference link");
}

Status planModel(const ModelDescription& desc, ModelRecord* model, ModelSpec* spec,
                 std::vector<InertiaWarning>* warnings) {
  std::map<std::string, int> index;
  for (const LinkDescription& link : desc.links) {
    index[link.name] = static_cast<int>(model->links.size());
    LinkRecord record;
    record.desc = link;
    model->links.push_back(record);
  }
  model->canonical = index.at(desc.canonical_link);
  for (const JointDescription& joint : desc.joints) {
    JointRecord record;
    record.desc = joint;
    record.parent = joint.parent == kWorldLink ? -1 : index.at(joint.parent);
    record.child = index.at(joint.child);
    model->links[record.child].parent_joint = static_cast<int>(model->joints.size());
    model->joints.push_back(record);
  }
  // Bodies: a link welded by a fixed joint to a moving parent shares its body; a link welded to
  // `world` (or in a static model) is anchored. The first link of a body is its reference.
  int body_count = 0;
  for (LinkRecord& link : model->links) {
    if (model->is_static) continue;
    if (link.parent_joint >= 0 && model->joints[link.parent_joint].desc.type == JointType::Fixed) {
      const int parent = model->joints[link.parent_joint].parent;
      link.body = parent < 0 ? -1 : model->links[parent].body;
      continue;
    }
    link.body = body_count++;
    link.sets_body_pose = true;
  }
  for (const LinkRecord& link : model->links) {
    const LinkDescription& d = link.desc;
    const double values[] = {d.mass, d.ixx, d.ixy, d.ixz, d.iyy, d.iyz, d.izz};
    for (double v : values)
      if (!std::isfinite(v)) return rejected("link '" + d.name + "' has a non-finite inertial");
    if (link.body >= 0 && d.has_inertial && d.mass < 0)
      return rejected("link '" + d.name + "' has a negative mass");
  }
  for (int body = 0; body < body_count; ++body) {
    BodySpec spec_body;
    MomentBounds bounds;
    const LumpFault fault = lumpBody(model, body, &spec_body, &bounds);
    const std::string& name = referenceLink(*model, body).desc.name;
    if (fault == LumpFault::NoMass)
      return rejected("link '" + name + "' moves but has no mass (give it an <inertial>)");
    if (fault == LumpFault::NotPositiveDefinite)
      return rejected("link '" + name + "' has an inertia that no rigid body can have");
    if (fault == LumpFault::MomentOutOfRange) {
      std::ostringstream why;
      why << "link '" << name << "' (with the links welded to it) has a principal moment of "
          << "inertia outside [" << kMinMoment << ", " << kMaxMoment << "] kg m^2";
      return rejected(why.str());
    }
    if (const std::optional<InertiaWarning> warning = inertiaWarning(*model, body, bounds))
      warnings->push_back(*warning);
    spec->bodies.push_back(spec_body);
  }
  for (LinkRecord& link : model->links) {
    link.first_anchored_shape = static_cast<int>(spec->anchored_shapes.size());
    for (const CollisionDescription& collision : link.desc.collisions)
      if (isAnchored(link, collision)) spec->anchored_shapes.push_back(shapeSpec(collision));
  }
  for (JointRecord& joint : model->joints) {
    const int child_body = model->links[joint.child].body;
    if (joint.desc.type == JointType::Fixed || child_body < 0) continue;
    joint.engine_joint = static_cast<int>(spec->joints.size());
    JointSpec spec_joint;
    spec_joint.prismatic = joint.desc.type == JointType::Prismatic;
    spec_joint.parent = joint.parent < 0 ? -1 : model->links[joint.parent].body;
    spec_joint.child = child_body;
    spec_joint.has_limits = joint.desc.has_limits;
    spec_joint.lower = joint.desc.lower;
    spec_joint.upper = joint.desc.upper;
    spec_joint.friction = joint.desc.friction;
    spec->joints.push_back(spec_joint);
  }
  // The bodies each joint moves: every body below it in the tree.
  for (const LinkRecord& link : model->links) {
    if (link.body < 0 || !link.sets_body_pose) continue;
    for (int j = link.parent_joint; j >= 0;
         j = model->joints[j].parent < 0 ? -1 : model->links[model->joints[j].parent].parent_joint)
      if (model->joints[j].engine_joint >= 0) model->joints[j].moved_bodies.push_back(link.body);
  }
  model->bodies = spec->bodies;
  return {};
}

}  // namespace core

std::vector<Pose> World::Impl::forwardKinematics(const ModelRecord& model, const Pose& frame_pose,
                                                 const std::vector<Pose>& root_poses,
                                                 const std::vector<double>& q) const {
  std::vector<Pose> poses(model.links.size());
  for (size_t i = 0; i < model.links.size(); ++i) {
    const int j = model.links[i].parent_joint;
    if (j < 0) {
      poses[i] = root_poses[i];
      continue;
    }
    const JointRecord& joint = model.joints[j];
    // Maps model-frame (zero configuration) coordinates to the world as the parent sits now.
    const Pose parent_mapping =
        joint.parent < 0 ? frame_pose
                         : compose(poses[joint.parent], inverse(model.links[joint.parent].desc.pose));
    poses[i] = compose(compose(parent_mapping, jointMotion(joint.desc, q[j])),
                       model.links[i].desc.pose);
  }
  return poses;
}

std::vector<Pose> World::Impl::placeLinks(ModelRecord* model, const std::vector<Pose>& poses) {
  std::vector<Pose> body_poses(model->bodies.size());
  for (size_t i = 0; i < model->links.size(); ++i) {
    LinkRecord& link = model->links[i];
    int shape = link.first_anchored_shape;
    for (const CollisionDescription& collision : link.desc.collisions)
      if (isAnchored(link, collision))
        model->engine_model->setAnchoredShapePose(shape++, compose(poses[i], collision.pose));
    if (link.body < 0) link.anchored_pose = poses[i];
    else if (link.sets_body_pose) body_poses[link.body] = compose(poses[i], inverse(link.link_in_body));
  }
  return body_poses;
}

void World::Impl::placeModel(ModelRecord* model, const Pose& frame_pose,
                             const std::vector<Pose>& root_poses, const std::vector<double>& q) {
  model->frame_pose = frame_pose;
  const std::vector<Pose> zero_poses =
      forwardKinematics(*model, frame_pose, root_poses, std::vector<double>(q.size(), 0.0));
  const std::vector<Pose> zero_body_poses = placeLinks(model, zero_poses);
  std::vector<JointFrame> frames;
  for (const JointRecord& joint : model->joints) {
    if (joint.engine_joint < 0) continue;
    const LinkRecord& child = model->links[joint.child];
    const Pose mapping = compose(zero_poses[joint.child], inverse(child.desc.pose));
    frames.push_back({transformPoint(mapping, joint.desc.anchor),
                      rotate(mapping.orientation, joint.desc.axis)});
  }
  model->engine_model->attachJoints(zero_body_poses, frames);
  const std::vector<Pose> body_poses =
      placeLinks(model, forwardKinematics(*model, frame_pose, root_poses, q));
  for (size_t body = 0; body < body_poses.size(); ++body)
    model->engine_model->setBodyState(static_cast<int>(body), body_poses[body], Twist());
  for (size_t j = 0; j < model->joints.size(); ++j) {
    JointRecord& joint = model->joints[j];
    joint.position = joint.engine_joint >= 0 ? q[j] : 0;
    if (joint.engine_joint >= 0)
      joint.last_raw = model->engine_model->jointPosition(joint.engine_joint);
  }
  model->velocity_capped = false;
  model->blown_up = false;
}

std::vector<Pose> World::Impl::currentLinkPoses(const ModelRecord& model) const {
  std::vector<Pose> poses;
  for (const LinkRecord& link : model.links) poses.push_back(linkWorldPose(model, link));
  return poses;
}

Status World::Impl::reweighLink(ModelRecord* model, size_t index, const LinkDescription& desc,
                                std::optional<InertiaWarning>* warning) {
  LinkRecord& link = model->links[index];
  const int body = link.body;
  const std::vector<Pose> poses = currentLinkPoses(*model);
  std::vector<Twist> twists;
  for (const LinkRecord& l : model->links) twists.push_back(linkWorldTwist(*model, l));
  const std::vector<double> q = currentPositions(*model);
  const LinkDescription previous = link.desc;
  link.desc = desc;
  BodySpec spec;
  MomentBounds bounds;
  const LumpFault fault = lumpBody(model, body, &spec, &bounds);
  if (fault != LumpFault::None) {
    link.desc = previous;
    if (fault == LumpFault::MomentOutOfRange) return outOfRange("inertia", bounds.min, bounds.max);
    return {StatusCode::InvalidParameter, fault == LumpFault::NoMass ? "mass" : "inertia"};
  }
  *warning = inertiaWarning(*model, body, bounds);
  model->bodies[body] = spec;
  model->engine_model->setBodyMass(body, spec);
  placeModel(model, model->frame_pose, poses, q);
  // placeModel leaves the model at rest: each body takes back the motion of its reference link.
  for (size_t i = 0; i < model->links.size(); ++i) {
    const LinkRecord& reference = model->links[i];
    if (reference.body < 0 || !reference.sets_body_pose) continue;
    const Pose body_pose = model->engine_model->bodyPose(reference.body);
    const Vec3 v = twists[i].linear + cross(twists[i].angular, body_pose.position - poses[i].position);
    model->engine_model->setBodyState(reference.body, body_pose, {v, twists[i].angular});
  }
  return {};
}

std::vector<double> World::Impl::currentPositions(const ModelRecord& model) const {
  std::vector<double> q;
  for (const JointRecord& joint : model.joints) q.push_back(joint.position);
  return q;
}

void World::Impl::resetModel(ModelRecord* model) {
  std::vector<Pose> root_poses;
  for (const LinkRecord& link : model->links)
    root_poses.push_back(compose(model->spawn_pose, link.desc.pose));
  placeModel(model, model->spawn_pose, root_poses,
             std::vector<double>(model->joints.size(), 0.0));
}

}  // namespace onedof_sim
