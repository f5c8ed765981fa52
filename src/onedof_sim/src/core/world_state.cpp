// Lookups of models, links, joints and reference frames, and the state and property getters and
// setters of models, links and joints.
#include <algorithm>
#include <cmath>

#include "world_impl.h"

namespace onedof_sim {

using namespace core;

Pose World::Impl::linkWorldPose(const ModelRecord& model, const LinkRecord& link) const {
  return link.body >= 0 ? compose(model.engine_model->bodyPose(link.body), link.link_in_body)
                        : link.anchored_pose;
}

Pose World::Impl::modelFramePose(const ModelRecord& model) const {
  const LinkRecord& canonical = model.links[model.canonical];
  return compose(linkWorldPose(model, canonical), inverse(canonical.desc.pose));
}

Twist World::Impl::linkWorldTwist(const ModelRecord& model, const LinkRecord& link) const {
  if (link.body < 0) return Twist();
  const Pose body_pose = model.engine_model->bodyPose(link.body);
  const Twist body = model.engine_model->bodyTwist(link.body);
  const Vec3 origin = transformPoint(body_pose, link.link_in_body.position);
  return {body.linear + cross(body.angular, origin - body_pose.position), body.angular};
}

double World::Impl::jointRate(const ModelRecord& model, const JointRecord& joint) const {
  return joint.engine_joint < 0 ? 0 : model.engine_model->jointRate(joint.engine_joint);
}

JointFrame World::Impl::jointFrame(const ModelRecord& model, const JointRecord& joint) const {
  const LinkRecord& child = model.links[joint.child];
  const Pose mapping = compose(linkWorldPose(model, child), inverse(child.desc.pose));
  return {transformPoint(mapping, joint.desc.anchor), rotate(mapping.orientation, joint.desc.axis)};
}

void World::Impl::updateJointPositions(ModelRecord* model) {
  for (JointRecord& joint : model->joints) {
    if (joint.engine_joint < 0) continue;
    const double raw = model->engine_model->jointPosition(joint.engine_joint);
    joint.position = joint.desc.type == JointType::Prismatic
                         ? raw
                         : joint.position + std::remainder(raw - joint.last_raw, 2 * M_PI);
    joint.last_raw = raw;
  }
}

ModelRecord* World::Impl::findModel(const std::string& name) const {
  for (const auto& model : models)
    if (model->name == name) return model.get();
  return nullptr;
}

bool World::Impl::findLink(const std::string& scoped, ModelRecord** model, size_t* link) const {
  for (const auto& m : models) {
    const std::string prefix = m->name + "::";
    if (scoped.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string bare = scoped.substr(prefix.size());
    for (size_t i = 0; i < m->links.size(); ++i)
      if (m->links[i].desc.name == bare) {
        *model = m.get();
        *link = i;
        return true;
      }
  }
  return false;
}

bool World::Impl::findJoint(const std::string& name, ModelRecord** model, size_t* joint) const {
  for (bool scoped : {true, false})
    for (const auto& m : models) {
      const std::string prefix = m->name + "::";
      if (scoped && name.compare(0, prefix.size(), prefix) != 0) continue;
      const std::string bare = scoped ? name.substr(prefix.size()) : name;
      for (size_t i = 0; i < m->joints.size(); ++i)
        if (m->joints[i].desc.name == bare) {
          *model = m.get();
          *joint = i;
          return true;
        }
    }
  return false;
}

bool World::Impl::resolveFrame(const std::string& name, Pose* pose, Twist* twist) const {
  *pose = Pose();
  *twist = Twist();
  if (name.empty() || name == kWorldLink) return true;
  ModelRecord* model = findModel(name);
  size_t link = 0;
  if (model) {
    *pose = modelFramePose(*model);
    *twist = linkWorldTwist(*model, model->links[model->canonical]);
    return true;
  }
  if (!findLink(name, &model, &link)) return false;
  *pose = linkWorldPose(*model, model->links[link]);
  *twist = linkWorldTwist(*model, model->links[link]);
  return true;
}

Status World::modelProperties(const std::string& name, ModelInfo* out) const {
  const ModelRecord* model = impl_->findModel(name);
  if (!model) return {StatusCode::ModelNotFound, name};
  ModelInfo info;
  info.name = model->name;
  info.canonical_link = model->name + "::" + model->links[model->canonical].desc.name;
  for (const LinkRecord& link : model->links) {
    info.links.push_back(model->name + "::" + link.desc.name);
    for (const CollisionDescription& collision : link.desc.collisions)
      info.geoms.push_back(collision.name);
  }
  for (const JointRecord& joint : model->joints) info.joints.push_back(joint.desc.name);
  info.is_static = model->is_static;
  *out = info;
  return {};
}

// Gazebo's convention for a state relative to an entity: pose in the entity frame, velocities
// relative to the entity's and expressed in its axes.
static void makeRelative(const Pose& frame, const Twist& frame_twist, Pose* pose, Twist* twist) {
  const Quat to_frame = conjugate(frame.orientation);
  *pose = compose(inverse(frame), *pose);
  twist->linear = rotate(to_frame, twist->linear - frame_twist.linear);
  twist->angular = rotate(to_frame, twist->angular - frame_twist.angular);
}

Status World::modelState(const std::string& name, const std::string& reference_frame, Pose* pose,
                         Twist* twist) const {
  const ModelRecord* model = impl_->findModel(name);
  if (!model) return {StatusCode::ModelNotFound, name};
  Pose frame;
  Twist frame_twist;
  if (!impl_->resolveFrame(reference_frame, &frame, &frame_twist))
    return {StatusCode::ReferenceFrameNotFound, reference_frame};
  *pose = impl_->modelFramePose(*model);
  *twist = impl_->linkWorldTwist(*model, model->links[model->canonical]);
  makeRelative(frame, frame_twist, pose, twist);
  return {};
}

Status World::setModelState(const std::string& name, const Pose& pose, const Twist& twist,
                            const std::string& reference_frame) {
  const Status state = checkState(pose, twist, impl_->params.step);
  if (!state.ok()) return state;
  ModelRecord* model = impl_->findModel(name);
  if (!model) return {StatusCode::ModelNotFound, name};
  Pose frame;
  Twist unused;
  if (!impl_->resolveFrame(reference_frame, &frame, &unused))
    return {StatusCode::ReferenceFrameNotFound, reference_frame};
  // The model frame goes to the target, the whole model moving rigidly with it.
  const Pose target = compose(frame, {pose.position, normalized(pose.orientation)});
  const Pose motion = compose(target, inverse(impl_->modelFramePose(*model)));
  std::vector<Pose> root_poses = impl_->currentLinkPoses(*model);
  for (Pose& p : root_poses) p = compose(motion, p);
  impl_->placeModel(model, compose(motion, model->frame_pose), root_poses,
                    impl_->currentPositions(*model));
  // The twist is the canonical link origin's (what modelState gives back), every body moving
  // rigidly with it.
  const Vec3 origin = impl_->linkWorldPose(*model, model->links[model->canonical]).position;
  const Vec3 linear = rotate(frame.orientation, twist.linear);
  const Vec3 angular = rotate(frame.orientation, twist.angular);
  for (size_t body = 0; body < model->bodies.size(); ++body) {
    const Pose body_pose = model->engine_model->bodyPose(body);
    const Vec3 v = linear + cross(angular, body_pose.position - origin);
    model->engine_model->setBodyState(body, body_pose, {v, angular});
  }
  return {};
}

Status World::setModelConfiguration(const std::string& model_name,
                                    const std::vector<std::string>& joints,
                                    const std::vector<double>& positions) {
  if (joints.size() != positions.size()) return {StatusCode::LengthMismatch, {}};
  for (size_t i = 0; i < joints.size(); ++i) {
    if (!std::isfinite(positions[i])) return {StatusCode::NotFinite, joints[i]};
    // Joint positions are kept unwrapped: past kMaxPosition a step's motion is lost in rounding.
    if (std::abs(positions[i]) > kMaxPosition)
      return outOfRange(joints[i], -kMaxPosition, kMaxPosition);
  }
  ModelRecord* model = impl_->findModel(model_name);
  if (!model) return {StatusCode::ModelNotFound, model_name};
  std::vector<double> q = impl_->currentPositions(*model);
  for (size_t i = 0; i < joints.size(); ++i) {
    auto joint = std::find_if(model->joints.begin(), model->joints.end(),
                              [&](const JointRecord& j) { return j.desc.name == joints[i]; });
    if (joint == model->joints.end()) return {StatusCode::JointNotFound, joints[i]};
    q[joint - model->joints.begin()] = positions[i];
  }
  impl_->placeModel(model, model->frame_pose, impl_->currentLinkPoses(*model), q);
  return {};
}

Status World::linkProperties(const std::string& scoped_link, LinkInfo* out) const {
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return {StatusCode::LinkNotFound, scoped_link};
  const LinkDescription& link = model->links[index].desc;
  LinkInfo info;
  info.model = model->name;
  info.name = link.name;
  info.com = link.com;
  info.mass = link.mass;
  info.ixx = link.ixx, info.ixy = link.ixy, info.ixz = link.ixz;
  info.iyy = link.iyy, info.iyz = link.iyz, info.izz = link.izz;
  info.gravity_mode = link.gravity;
  *out = info;
  return {};
}

Status World::linkState(const std::string& scoped_link, const std::string& reference_frame,
                        Pose* pose, Twist* twist) const {
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return {StatusCode::LinkNotFound, scoped_link};
  Pose frame;
  Twist frame_twist;
  if (!impl_->resolveFrame(reference_frame, &frame, &frame_twist))
    return {StatusCode::ReferenceFrameNotFound, reference_frame};
  *pose = impl_->linkWorldPose(*model, model->links[index]);
  *twist = impl_->linkWorldTwist(*model, model->links[index]);
  makeRelative(frame, frame_twist, pose, twist);
  return {};
}

Status World::setLinkState(const std::string& scoped_link, const Pose& pose, const Twist& twist,
                           const std::string& reference_frame) {
  const Status state = checkState(pose, twist, impl_->params.step);
  if (!state.ok()) return state;
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return {StatusCode::LinkNotFound, scoped_link};
  const LinkRecord& link = model->links[index];
  if (link.body < 0) return {StatusCode::LinkAnchored, scoped_link};
  Pose frame;
  Twist unused;
  if (!impl_->resolveFrame(reference_frame, &frame, &unused))
    return {StatusCode::ReferenceFrameNotFound, reference_frame};
  // As Gazebo: only this link's body moves; its joints pull it back in the next steps.
  const Pose target = compose(frame, {pose.position, normalized(pose.orientation)});
  const Pose body_pose = compose(target, inverse(link.link_in_body));
  const Vec3 linear = rotate(frame.orientation, twist.linear);
  const Vec3 angular = rotate(frame.orientation, twist.angular);
  const Vec3 v = linear + cross(angular, body_pose.position - target.position);
  model->engine_model->setBodyState(link.body, body_pose, {v, angular});
  impl_->updateJointPositions(model);
  return {};
}

Status World::setLinkProperties(const std::string& scoped_link, const LinkInfo& properties,
                                std::optional<InertiaWarning>* warning) {
  std::optional<InertiaWarning> unused;
  if (!warning) warning = &unused;
  warning->reset();
  const Status com = checkPose(properties.com);
  if (!com.ok()) return {com.code, "com"};
  if (!std::isfinite(properties.mass)) return {StatusCode::NotFinite, "mass"};
  const double moments[] = {properties.ixx, properties.ixy, properties.ixz,
                            properties.iyy, properties.iyz, properties.izz};
  for (double moment : moments)
    if (!std::isfinite(moment)) return {StatusCode::NotFinite, "inertia"};
  if (properties.mass < 0) return {StatusCode::InvalidParameter, "mass"};
  if (properties.mass != 0 && (properties.mass < kMinMass || properties.mass > kMaxMass))
    return outOfRange("mass", kMinMass, kMaxMass);
  for (double moment : moments)
    if (std::abs(moment) > kMaxMoment) return outOfRange("inertia", kMinMoment, kMaxMoment);
  if (!withinPosition(properties.com.position))
    return outOfRange("com.position", -kMaxPosition, kMaxPosition);
  ModelRecord* model;
  size_t index;
  if (!impl_->findLink(scoped_link, &model, &index))
    return {StatusCode::LinkNotFound, scoped_link};
  LinkRecord& link = model->links[index];
  LinkDescription desc = link.desc;
  desc.has_inertial = true;
  desc.mass = properties.mass;
  desc.com = {properties.com.position, normalized(properties.com.orientation)};
  desc.ixx = properties.ixx, desc.ixy = properties.ixy, desc.ixz = properties.ixz;
  desc.iyy = properties.iyy, desc.iyz = properties.iyz, desc.izz = properties.izz;
  desc.gravity = properties.gravity_mode;
  if (link.body < 0) {  // anchored: nothing it carries moves
    link.desc = desc;
    return {};
  }
  // An engine body has one gravity mode.
  for (const LinkRecord& other : model->links)
    if (&other != &link && other.body == link.body && other.desc.gravity != desc.gravity)
      return {StatusCode::InvalidParameter, "gravity_mode"};
  return impl_->reweighLink(model, index, desc, warning);
}

std::vector<std::string> World::linkNames() const {
  std::vector<std::string> names;
  for (const auto& model : impl_->models)
    for (const LinkRecord& link : model->links) names.push_back(model->name + "::" + link.desc.name);
  return names;
}

Status World::jointInfo(const std::string& joint_name, JointInfo* out) const {
  ModelRecord* model;
  size_t index;
  if (!impl_->findJoint(joint_name, &model, &index))
    return {StatusCode::JointNotFound, joint_name};
  const JointRecord& joint = model->joints[index];
  JointInfo info;
  info.model = model->name;
  info.name = joint.desc.name;
  info.type = joint.desc.type;
  info.has_damping = joint.desc.has_damping;
  info.damping = joint.desc.damping;
  info.position = joint.position;
  info.rate = impl_->jointRate(*model, joint);
  info.has_limits = joint.desc.has_limits;
  info.lower = joint.desc.lower;
  info.upper = joint.desc.upper;
  *out = info;
  return {};
}

Status World::jointConstraintWrench(const std::string& joint_name, Wrench* out) const {
  ModelRecord* model;
  size_t index;
  if (!impl_->findJoint(joint_name, &model, &index))
    return {StatusCode::JointNotFound, joint_name};
  const JointRecord& joint = model->joints[index];
  if (joint.engine_joint < 0) return {StatusCode::JointIsFixed, joint_name};
  const Wrench at_com = model->engine_model->jointConstraintWrench(joint.engine_joint);
  const int body = model->links[joint.child].body;
  const Vec3 com = model->engine_model->bodyPose(body).position;
  const Vec3 anchor = impl_->jointFrame(*model, joint).anchor;
  // The same force through the centre of mass, moved to the anchor: r x f with r from the
  // anchor to the centre of mass.
  *out = {at_com.force, at_com.torque + cross(com - anchor, at_com.force)};
  return {};
}

Status World::setJointDamping(const std::string& joint_name, double damping) {
  ModelRecord* model;
  size_t index;
  if (!impl_->findJoint(joint_name, &model, &index))
    return {StatusCode::JointNotFound, joint_name};
  JointRecord& joint = model->joints[index];
  if (joint.engine_joint < 0) return {StatusCode::JointIsFixed, joint_name};
  if (!std::isfinite(damping)) return {StatusCode::NotFinite, "damping"};
  if (damping < 0) return {StatusCode::InvalidParameter, "damping"};
  if (damping > kMaxJointDamping) return outOfRange("damping", 0, kMaxJointDamping);
  joint.desc.damping = damping;
  joint.desc.has_damping = true;
  return {};
}

}  // namespace onedof_sim
