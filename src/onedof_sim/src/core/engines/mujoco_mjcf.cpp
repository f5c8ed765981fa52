// The MJCF text of the MuJoCo engine's models (mujoco_engine.cpp) and its compile: the options
// and defaults every compile shares, shapes, meshes and inertias as MuJoCo 2.2 takes them.
#include "mujoco_mjcf.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>

#include "onedof_sim/pose_math.h"

namespace onedof_sim {
namespace core {
namespace mjcf {
namespace {

// The solver reference (solref) of contacts and joint limits: a time constant of four steps,
// critically damped. At two, the least MuJoCo's refsafe allows, a cylinder spun on its end face
// hops on its rim points and is thrown.
constexpr double kContactSteps = 4;
// The solver reference of the rows that hold a joint's rate (friction, a velocity motor): a time
// constant below any step, which refsafe raises to two steps, so that a motor reaches its
// velocity within a step.
constexpr const char* kStiffestReference = "1e-9 1";
// Impedance (solimp) of contacts and joint limits, and of the rate rows: MuJoCo's largest,
// 0.9999 (mjMAXIMP).
constexpr const char* kContactImpedance = "0.99 0.99 0.001";
constexpr const char* kRowImpedance = "0.9999 0.9999 0.001";
// Friction rows of a contact are this much stiffer than its normal (MuJoCo's impratio). At 1 and
// at 100 a cylinder spun on its end face is thrown.
constexpr double kImpRatio = 10;
// A mesh is flat when no vertex is further from its largest triangle's plane than this fraction
// of its size; MuJoCo collides it as a plate this thick (m).
constexpr double kFlatMeshTolerance = 1e-9;
constexpr double kFlatMeshThickness = 1e-4;
// Newton's tolerance.
constexpr double kTolerance = 1e-10;

// A mesh whose vertices lie in one plane (a plate of triangles) has no hull that MuJoCo can take:
// it is given the hull of its vertices and of their copies moved by the returned offset,
// kFlatMeshThickness behind its largest triangle's face. Nothing for a mesh with volume, and for
// one with no triangle of any area (MuJoCo refuses it).
std::optional<Vec3> flatBack(const TriangleMesh& mesh) {
  Vec3 normal;
  double largest = 0, extent = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3 n = cross(mesh.vertices[t[1]] - a, mesh.vertices[t[2]] - a);
    if (norm(n) > largest) largest = norm(n), normal = (1 / norm(n)) * n;
  }
  if (!(largest > 0)) return std::nullopt;
  const Vec3& origin = mesh.vertices[mesh.triangles[0][0]];
  double off_plane = 0;
  for (const Vec3& v : mesh.vertices) {
    off_plane = std::max(off_plane, std::fabs(dot(v - origin, normal)));
    extent = std::max(extent, norm(v - origin));
  }
  if (off_plane > kFlatMeshTolerance * extent) return std::nullopt;
  return -kFlatMeshThickness * normal;
}

}  // namespace

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}
std::string vector(const Vec3& v) { return number(v.x) + " " + number(v.y) + " " + number(v.z); }
std::string quaternion(const Quat& q) {
  return number(q.w) + " " + number(q.x) + " " + number(q.y) + " " + number(q.z);
}
std::string placement(const Pose& pose) {
  return " pos=\"" + vector(pose.position) + "\" quat=\"" + quaternion(pose.orientation) + "\"";
}

// The MJCF head every compile shares: radians, inertias as given, the stiff soft constraints.
std::string head(const PhysicsParams& params, int njmax) {
  const std::string contact_reference = number(kContactSteps * params.step) + " 1";
  return "<mujoco model=\"onedof_sim\"><compiler angle=\"radian\" inertiafromgeom=\"false\" "
         "boundmass=\"0\" boundinertia=\"0\"/>"
         "<size njmax=\"" + std::to_string(njmax) + "\" nconmax=\"" + std::to_string(njmax / 3) +
         "\"/><option timestep=\"" + number(params.step) + "\" gravity=\"" +
         vector(params.gravity) +
         "\" integrator=\"Euler\" solver=\"Newton\" cone=\"elliptic\" impratio=\"" +
         number(kImpRatio) + "\" iterations=\"" +
         std::to_string(std::max<int>(kMinIterations, static_cast<int>(params.sor_pgs_iters))) +
         "\" tolerance=\"" + number(kTolerance) + "\"/>"
         "<default><geom condim=\"3\" margin=\"0\" solref=\"" + contact_reference +
         "\" solimp=\"" + kContactImpedance + "\"/><joint damping=\"0\" armature=\"0\" "
         "solreflimit=\"" + contact_reference + "\" solimplimit=\"" + kContactImpedance +
         "\" solreffriction=\"" + kStiffestReference + "\" solimpfriction=\"" + kRowImpedance +
         "\"/></default>";
}

// A geom element's type and size, and a mesh's asset.
std::string geom(const ShapeSpec& shape, const std::string& mesh_name, std::string* assets) {
  const Vec3& s = shape.size;
  switch (shape.shape) {
    case GeometryShape::Box: return "type=\"box\" size=\"" + vector(0.5 * s) + "\"";
    case GeometryShape::Cylinder:
      return "type=\"cylinder\" size=\"" + number(s.x) + " " + number(s.z / 2) + "\"";
    case GeometryShape::Sphere: return "type=\"sphere\" size=\"" + number(s.x) + "\"";
    case GeometryShape::Plane: return "type=\"plane\" size=\"0 0 1\"";
    case GeometryShape::Mesh: {
      *assets += "<mesh name=\"" + mesh_name + "\" vertex=\"";
      for (const Vec3& v : shape.mesh->vertices) *assets += vector(v) + " ";
      if (const std::optional<Vec3> back = flatBack(*shape.mesh))
        for (const Vec3& v : shape.mesh->vertices) *assets += vector(v + *back) + " ";
      *assets += "\"/>";
      return "type=\"mesh\" mesh=\"" + mesh_name + "\"";
    }
  }
  return "";
}

// A body's inertia as MJCF attributes. MuJoCo refuses principal moments A <= B <= C with A + B < C,
// which no rigid body has and the other engines take: the largest moment is lowered to A + B
// (a flat plate's, the nearest a body can have).
std::string inertia(const BodySpec& spec) {
  const mjtNum tensor[9] = {spec.ixx, spec.ixy, spec.ixz, spec.ixy, spec.iyy,
                            spec.iyz, spec.ixz, spec.iyz, spec.izz};
  mjtNum moments[3], axes[9], axes_quat[4];
  mju_eig3(moments, axes, axes_quat, tensor);  // moments in decreasing order
  if (moments[1] + moments[2] >= moments[0])
    return "fullinertia=\"" + vector({spec.ixx, spec.iyy, spec.izz}) + " " +
           vector({spec.ixy, spec.ixz, spec.iyz}) + "\"";
  return "quat=\"" + quaternion({axes_quat[0], axes_quat[1], axes_quat[2], axes_quat[3]}) +
         "\" diaginertia=\"" + vector({moments[1] + moments[2], moments[1], moments[2]}) + "\"";
}

// An MJCF model's compile, with MuJoCo's message when it fails.
mjModel* compile(const std::string& xml, std::string* error) {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* file = "world.xml";
  mj_makeEmptyFileVFS(vfs.get(), file, static_cast<int>(xml.size()));
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), file)], xml.data(), xml.size());
  char text[1000] = "";
  mjModel* model = mj_loadXML(file, vfs.get(), text, sizeof text);
  mj_deleteVFS(vfs.get());
  if (!model) *error = text;
  return model;
}

}  // namespace mjcf
}  // namespace core
}  // namespace onedof_sim
