// The last step's contacts (World::contacts): the engine's contact points, named by the
// collisions they are between and with the wrench each put on the two links.
#include <string>
#include <utility>
#include <vector>

#include "world_impl.h"

namespace onedof_sim {

using namespace core;

bool World::Impl::findCollision(const std::string& scoped, ShapeRef* shape) const {
  const size_t split = scoped.rfind("::");
  if (split == std::string::npos) return false;
  ModelRecord* model;
  size_t index;
  if (!findLink(scoped.substr(0, split), &model, &index)) return false;
  const std::string name = scoped.substr(split + 2);
  const LinkRecord& link = model->links[index];
  for (size_t c = 0; c < link.desc.collisions.size(); ++c) {
    if (link.desc.collisions[c].name != name) continue;
    if (link.body < 0) {
      *shape = {model->engine_model.get(), -1, link.first_anchored_shape + static_cast<int>(c)};
      return true;
    }
    // A body's shapes are its links' collisions, link after link (lumpBody).
    int first = 0;
    for (size_t l = 0; l < index; ++l)
      if (model->links[l].body == link.body)
        first += static_cast<int>(model->links[l].desc.collisions.size());
    *shape = {model->engine_model.get(), link.body, first + static_cast<int>(c)};
    return true;
  }
  return false;
}

bool World::Impl::describeShape(const ShapeRef& shape, std::string* name, Vec3* centre) const {
  for (const auto& model : models) {
    if (model->engine_model.get() != shape.model) continue;
    int first = 0;
    for (const LinkRecord& link : model->links) {
      if (link.body != shape.body) continue;
      const int count = static_cast<int>(link.desc.collisions.size());
      const int start = link.body < 0 ? link.first_anchored_shape : first;
      first += count;
      if (shape.shape < start || shape.shape >= start + count) continue;
      *name = model->name + "::" + link.desc.name + "::" +
              link.desc.collisions[shape.shape - start].name;
      *centre = link.body >= 0 ? model->engine_model->bodyPose(link.body).position
                               : compose(link.anchored_pose, link.desc.com).position;
      return true;
    }
    return false;
  }
  return false;
}

Status World::contacts(const std::vector<std::string>& collisions,
                       std::vector<Contact>* out) const {
  out->clear();
  std::vector<ShapeRef> wanted(collisions.size());
  for (size_t i = 0; i < collisions.size(); ++i)
    if (!impl_->findCollision(collisions[i], &wanted[i]))
      return {StatusCode::CollisionNotFound, collisions[i]};
  if (!impl_->contacts_current || wanted.empty()) return {};
  std::vector<EngineContact> points;
  impl_->engine->contacts(&points);
  auto rank = [&](const ShapeRef& shape) {
    for (size_t i = 0; i < wanted.size(); ++i)
      if (wanted[i] == shape) return i;
    return wanted.size();
  };
  // Per Contact in *out: its two shapes and the points its torques are about.
  struct Pair {
    ShapeRef first, second;
    Vec3 centre1, centre2;
  };
  std::vector<Pair> pairs;
  for (const EngineContact& point : points) {
    const size_t rank_a = rank(point.a), rank_b = rank(point.b);
    if (rank_a == wanted.size() && rank_b == wanted.size()) continue;
    const bool swap = rank_b < rank_a;
    const ShapeRef& first = swap ? point.b : point.a;
    const ShapeRef& second = swap ? point.a : point.b;
    size_t index = 0;
    while (index < pairs.size() && !(pairs[index].first == first && pairs[index].second == second))
      ++index;
    if (index == pairs.size()) {
      Contact contact;
      Pair pair{first, second, {}, {}};
      if (!impl_->describeShape(first, &contact.collision1, &pair.centre1) ||
          !impl_->describeShape(second, &contact.collision2, &pair.centre2))
        continue;
      pairs.push_back(pair);
      out->push_back(std::move(contact));
    }
    const Pair& pair = pairs[index];
    const double sign = swap ? -1 : 1;
    const Vec3 force = sign * point.force;
    ContactPoint contact_point;
    contact_point.position = point.position;
    contact_point.normal = sign * point.normal;
    contact_point.depth = point.depth;
    contact_point.wrench1 = {force, cross(point.position - pair.centre1, force)};
    contact_point.wrench2 = {-force, cross(point.position - pair.centre2, -force)};
    (*out)[index].points.push_back(contact_point);
  }
  return {};
}

}  // namespace onedof_sim
