#include "visual_loader.h"

#include <tinyxml2.h>

#include <cmath>
#include <filesystem>

#include "mesh_loader.h"
#include "onedof_sim/pose_math.h"
#include "onedof_sim/trim.h"
#include "sdf_parsing.h"

namespace onedof_sim {
namespace core {
namespace {

// Gazebo's URDF conversion names unnamed visuals so (LINK_visual, LINK_visual_1, ...).
std::string visualName(const std::string& given, const std::string& link, size_t index) {
  if (!given.empty()) return given;
  return link + "_visual" + (index == 0 ? "" : "_" + std::to_string(index));
}

Pose urdfPose(const urdf::Pose& p) {
  return {{p.position.x, p.position.y, p.position.z},
          normalized({p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z})};
}

Color toColor(const ignition::math::Color& c) { return {c.R(), c.G(), c.B(), c.A()}; }

}  // namespace

void addUrdfVisuals(const urdf::Link& urdf_link, const std::string& gazebo_material,
                    const std::vector<std::string>& model_path, LinkDescription* link) {
  // urdfdom keeps a lone <visual> only in `visual`, several in `visual_array`.
  std::vector<urdf::VisualSharedPtr> visuals = urdf_link.visual_array;
  if (visuals.empty() && urdf_link.visual) visuals.push_back(urdf_link.visual);
  for (size_t i = 0; i < visuals.size(); ++i) {
    const urdf::Visual& visual = *visuals[i];
    if (!visual.geometry) continue;  // urdfdom refuses a visual without geometry
    VisualDescription out;
    out.name = visualName(visual.name, link->name, i);
    out.pose = urdfPose(visual.origin);
    switch (visual.geometry->type) {
      case urdf::Geometry::BOX: {
        const auto& box = static_cast<const urdf::Box&>(*visual.geometry);
        out.shape = GeometryShape::Box;
        out.size = {box.dim.x, box.dim.y, box.dim.z};
        break;
      }
      case urdf::Geometry::CYLINDER: {
        const auto& cylinder = static_cast<const urdf::Cylinder&>(*visual.geometry);
        out.shape = GeometryShape::Cylinder;
        out.size = {cylinder.radius, 0, cylinder.length};
        break;
      }
      case urdf::Geometry::SPHERE:
        out.shape = GeometryShape::Sphere;
        out.size = {static_cast<const urdf::Sphere&>(*visual.geometry).radius, 0, 0};
        break;
      case urdf::Geometry::MESH: {
        const auto& mesh = static_cast<const urdf::Mesh&>(*visual.geometry);
        out.shape = GeometryShape::Mesh;
        out.size = {mesh.scale.x, mesh.scale.y, mesh.scale.z};
        out.mesh_uri = mesh.filename;
        out.mesh_file = resolveMeshUri(mesh.filename, model_path, "");
        break;
      }
      default:
        continue;
    }
    // A <gazebo reference> material names the colour Gazebo shows; the URDF colour is rviz's.
    if (!gazebo_material.empty()) {
      out.material.script = gazebo_material;
    } else if (visual.material) {
      const urdf::Color& c = visual.material->color;
      const Color color{c.r, c.g, c.b, c.a};
      out.material.ambient = color;
      out.material.diffuse = color;
    }
    link->visuals.push_back(out);
  }
}

bool addSdfVisuals(const sdf::Link& sdf_link, const std::vector<std::string>& model_path,
                   LinkDescription* link, std::string* error) {
  for (uint64_t i = 0; i < sdf_link.VisualCount(); ++i) {
    const sdf::Visual& visual = *sdf_link.VisualByIndex(i);
    VisualDescription out;
    out.name = visual.Name();
    ignition::math::Pose3d pose;
    const sdf::Errors errors = visual.SemanticPose().Resolve(pose, sdf_link.Name());
    if (!errors.empty()) {
      *error = "link '" + link->name + "': visual '" + out.name + "': " + joinErrors(errors);
      return false;
    }
    out.pose = toPose(pose);
    const sdf::Geometry& geometry = *visual.Geom();
    switch (geometry.Type()) {
      case sdf::GeometryType::BOX: {
        const auto& size = geometry.BoxShape()->Size();
        out.shape = GeometryShape::Box;
        out.size = {size.X(), size.Y(), size.Z()};
        break;
      }
      case sdf::GeometryType::CYLINDER:
        out.shape = GeometryShape::Cylinder;
        out.size = {geometry.CylinderShape()->Radius(), 0, geometry.CylinderShape()->Length()};
        break;
      case sdf::GeometryType::SPHERE:
        out.shape = GeometryShape::Sphere;
        out.size = {geometry.SphereShape()->Radius(), 0, 0};
        break;
      case sdf::GeometryType::PLANE: {
        const sdf::Plane& plane = *geometry.PlaneShape();
        out.shape = GeometryShape::Plane;
        out.size = {plane.Size().X(), plane.Size().Y(), 0};
        const auto& normal = plane.Normal();
        out.pose.orientation =
            multiply(out.pose.orientation, zTo({normal.X(), normal.Y(), normal.Z()}));
        break;
      }
      case sdf::GeometryType::MESH: {
        const sdf::Mesh& mesh = *geometry.MeshShape();
        const auto& scale = mesh.Scale();
        out.shape = GeometryShape::Mesh;
        out.size = {scale.X(), scale.Y(), scale.Z()};
        out.mesh_uri = mesh.Uri();
        const std::string folder =
            mesh.FilePath().empty() ? "" : std::filesystem::path(mesh.FilePath()).parent_path();
        out.mesh_file = resolveMeshUri(mesh.Uri(), model_path, folder);
        break;
      }
      default:
        continue;  // heightmaps, images, polylines: not drawn
    }
    if (const sdf::Material* material = visual.Material()) {
      out.material.script = material->ScriptName();
      const sdf::ElementPtr element = material->Element();
      const auto given = [&](const char* name) { return element && element->HasElement(name); };
      if (given("ambient")) out.material.ambient = toColor(material->Ambient());
      if (given("diffuse")) out.material.diffuse = toColor(material->Diffuse());
      if (given("emissive")) out.material.emissive = toColor(material->Emissive());
    }
    link->visuals.push_back(out);
  }
  return true;
}

}  // namespace core
}  // namespace onedof_sim
