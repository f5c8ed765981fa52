// What a view of the world draws, in world coordinates as the world is now: the collision and
// visual shapes, the joints, the links' masses and the last step's contacts (Gazebo's View menu).
#include <string>
#include <vector>

#include "onedof_sim/pose_math.h"
#include "onedof_sim/world.h"
#include "world_impl.h"

namespace onedof_sim {

using namespace core;

std::vector<CollisionShape> World::collisionShapes() const {
  std::vector<CollisionShape> shapes;
  for (const auto& model : impl_->models)
    for (const LinkRecord& link : model->links)
      for (const CollisionDescription& collision : link.desc.collisions) {
        CollisionShape shape;
        shape.model = model->name;
        shape.link = link.desc.name;
        shape.shape = collision.shape;
        shape.size = collision.size;
        shape.pose = compose(impl_->linkWorldPose(*model, link), collision.pose);
        if (collision.mesh) shape.mesh_file = collision.mesh->file;
        shapes.push_back(shape);
      }
  return shapes;
}

std::vector<VisualShape> World::visualShapes() const {
  std::vector<VisualShape> shapes;
  for (const auto& model : impl_->models)
    for (const LinkRecord& link : model->links) {
      if (link.desc.visuals.empty()) continue;
      const Pose link_pose = impl_->linkWorldPose(*model, link);
      for (const VisualDescription& visual : link.desc.visuals) {
        VisualShape shape;
        shape.model = model->name;
        shape.link = link.desc.name;
        shape.name = visual.name;
        shape.shape = visual.shape;
        shape.size = visual.size;
        shape.pose = compose(link_pose, visual.pose);
        shape.mesh_uri = visual.mesh_uri;
        shape.mesh_file = visual.mesh_file;
        shape.material = visual.material;
        shapes.push_back(shape);
      }
    }
  return shapes;
}

std::vector<JointAxis> World::jointAxes() const {
  std::vector<JointAxis> axes;
  for (const auto& model : impl_->models)
    for (const JointRecord& joint : model->joints) {
      // The description's anchor and axis are in the model frame with every joint at zero, where
      // the child link's frame is its description's pose: carried from there to where the child
      // link is now.
      const LinkRecord& child = model->links[joint.child];
      const Pose now = compose(impl_->linkWorldPose(*model, child), inverse(child.desc.pose));
      JointAxis axis;
      axis.model = model->name;
      axis.name = joint.desc.name;
      axis.type = joint.desc.type;
      axis.anchor = transformPoint(now, joint.desc.anchor);
      axis.axis = rotate(now.orientation, joint.desc.axis);
      axes.push_back(axis);
    }
  return axes;
}

std::vector<LinkMass> World::linkMasses() const {
  std::vector<LinkMass> masses;
  for (const auto& model : impl_->models)
    for (const LinkRecord& link : model->links) {
      const LinkDescription& d = link.desc;
      if (!d.has_inertial || !(d.mass > 0)) continue;
      LinkMass mass;
      mass.model = model->name;
      mass.link = d.name;
      mass.inertial = compose(impl_->linkWorldPose(*model, link), d.com);
      mass.mass = d.mass;
      mass.ixx = d.ixx, mass.ixy = d.ixy, mass.ixz = d.ixz;
      mass.iyy = d.iyy, mass.iyz = d.iyz, mass.izz = d.izz;
      masses.push_back(mass);
    }
  return masses;
}

std::vector<Contact> World::allContacts() const {
  // Static models' collisions named last: a moving model's collision is collision1 of its contacts
  // with the ground (or any static model), their normals pointing out of the static one.
  std::vector<std::string> collisions;
  for (const bool static_models : {false, true})
    for (const auto& model : impl_->models) {
      if (model->is_static != static_models) continue;
      for (const LinkRecord& link : model->links)
        for (const CollisionDescription& collision : link.desc.collisions)
          collisions.push_back(model->name + "::" + link.desc.name + "::" + collision.name);
    }
  std::vector<Contact> out;
  contacts(collisions, &out);  // every name is the world's own: never refused
  return out;
}

}  // namespace onedof_sim
