#include "mesh_loader.h"

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>

#include "mesh_precheck.h"
#include "model_description.h"
#include "regular_file.h"

namespace onedof_sim {
namespace core {

namespace fs = std::filesystem;

bool staysInside(const std::string& relative) {
  const fs::path normal = fs::path(relative).lexically_normal();
  return !normal.empty() && normal.is_relative() && *normal.begin() != "..";
}

std::string resolveMeshUri(const std::string& uri, const std::vector<std::string>& model_path,
                           const std::string& relative_to) {
  std::vector<fs::path> candidates;
  const size_t scheme_end = uri.find("://");
  const std::string scheme = scheme_end == std::string::npos ? "" : uri.substr(0, scheme_end);
  const std::string rest = scheme_end == std::string::npos ? uri : uri.substr(scheme_end + 3);
  if (scheme == "model" || scheme == "package") {
    if (staysInside(rest))
      for (const std::string& folder : model_path)
        candidates.push_back(fs::path(folder) / fs::path(rest).lexically_normal());
  } else if (scheme == "file") {
    candidates.push_back(rest);
  } else if (scheme.empty()) {
    if (fs::path(uri).is_absolute())
      candidates.push_back(uri);
    else if (!relative_to.empty())
      candidates.push_back(fs::path(relative_to) / uri);
  }
  for (const fs::path& candidate : candidates)
    if (checkRegularFile(candidate).readable()) return candidate.string();
  return "";
}

namespace {

std::string count(size_t n) { return std::to_string(n); }

}  // namespace

MeshReader::MeshReader()
    : limits_{kMaxMeshFileBytes, kMaxMeshTriangles, kMaxModelMeshTriangles, kMaxMeshPlacements,
              kMaxMeshDepth} {}

Status MeshReader::readRaw(const std::string& file, std::shared_ptr<const Raw>* out) {
  auto cached = files_.find(file);
  if (cached != files_.end()) {
    *out = cached->second;
    return {};
  }
  const MeshFormat format = meshFormatOf(file);
  if (format == MeshFormat::Unknown)
    return rejected("the mesh file " + file + " is not STL (.stl), COLLADA (.dae) or OBJ (.obj), "
                    "the formats Gazebo reads");
  std::string bytes;
  uintmax_t size = 0;
  switch (readRegularFile(file, limits_.file_bytes, &bytes, &size)) {
    case FileRead::Unreadable: return rejected("cannot read the mesh file " + file);
    case FileRead::TooLarge:
      return rejected("the mesh file " + file + " has " + count(size) + " bytes; at most " +
                      count(limits_.file_bytes) + " are accepted");
    case FileRead::Ok: break;
  }
  const auto too_many = [&](size_t triangles) {
    return rejected("the mesh file " + file + " has " + count(triangles) + " triangles; at most " +
                    count(limits_.mesh_triangles) + " are accepted per mesh");
  };
  // Its structure before assimp reads it: assimp would overflow its stack on a deep or
  // self-instancing hierarchy, and spend the memory of every placement before it is counted.
  const MeshShape shape =
      measureMesh(bytes, format, {limits_.mesh_triangles, limits_.placements, limits_.depth});
  switch (shape.code) {
    case MeshShapeCode::Ok: break;
    case MeshShapeCode::NotWellFormed:
      return rejected("cannot read the mesh file " + file + ": not well-formed XML: " +
                      shape.subject);
    case MeshShapeCode::TooDeep:
      return rejected("the mesh file " + file + " nests its " + shape.subject + " " +
                      (shape.subject == "nodes" ? count(shape.depth)
                                                : "more than " + count(shape.depth - 1)) +
                      " deep; at most " + count(limits_.depth) + " levels are accepted");
    case MeshShapeCode::InstanceCycle:
      return rejected("the mesh file " + file + " has a node that instances itself: " +
                      shape.subject);
    case MeshShapeCode::TooManyPlacements:
      return rejected("the mesh file " + file + " places " + count(shape.placements) +
                      " nodes and geometry instances; at most " + count(limits_.placements) +
                      " are accepted");
    case MeshShapeCode::TooManyTriangles: return too_many(shape.triangles);
  }
  Assimp::Importer importer;
  // A COLLADA file's coordinates as written: ROS meshes are z-up whatever up_axis says, and
  // assimp would otherwise turn a Z_UP file to y-up. Its <unit> still scales it to metres.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  // Points and lines are no collision surface: dropped.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // The bytes measured, read by the importer of their format (the extension tells it).
  const aiScene* scene = importer.ReadFileFromMemory(
      bytes.data(), bytes.size(),
      aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType,
      meshFormatExtension(format));
  bytes = std::string();
  if (!scene || !scene->mRootNode)
    return rejected("cannot read the mesh file " + file + ": " + importer.GetErrorString());
  size_t faces = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) faces += scene->mMeshes[m]->mNumFaces;
  if (faces > limits_.mesh_triangles) return too_many(faces);
  auto raw = std::make_shared<Raw>();
  // Every node places its meshes by the product of the transforms down to it; a mesh placed by
  // several nodes is there several times.
  std::function<Status(const aiNode&, const aiMatrix4x4&)> add = [&](const aiNode& node,
                                                                      const aiMatrix4x4& parent) {
    const aiMatrix4x4 transform = parent * node.mTransformation;
    for (unsigned i = 0; i < node.mNumMeshes; ++i) {
      const aiMesh& mesh = *scene->mMeshes[node.mMeshes[i]];
      const uint32_t first = static_cast<uint32_t>(raw->vertices.size());
      for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
        const aiVector3D p = transform * mesh.mVertices[v];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
          return rejected("the mesh file " + file + " has a non-finite vertex");
        raw->vertices.push_back({p.x, p.y, p.z});
      }
      for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
        const aiFace& face = mesh.mFaces[f];
        if (face.mNumIndices != 3) continue;
        raw->triangles.push_back(
            {first + face.mIndices[0], first + face.mIndices[1], first + face.mIndices[2]});
      }
      // A mesh its nodes place several times counts each time.
      if (raw->triangles.size() > limits_.mesh_triangles) return too_many(raw->triangles.size());
    }
    for (unsigned c = 0; c < node.mNumChildren; ++c) {
      Status status = add(*node.mChildren[c], transform);
      if (!status.ok()) return status;
    }
    return Status();
  };
  Status status = add(*scene->mRootNode, aiMatrix4x4());
  if (!status.ok()) return status;
  if (raw->triangles.empty()) return rejected("the mesh file " + file + " has no triangles");
  files_.emplace(file, raw);
  *out = raw;
  return {};
}

Status MeshReader::read(const std::string& file, const Vec3& scale,
                        std::shared_ptr<const TriangleMesh>* out) {
  std::shared_ptr<const Raw> raw;
  Status status = readRaw(file, &raw);
  if (!status.ok()) return status;
  model_triangles_ += raw->triangles.size();
  if (model_triangles_ > limits_.model_triangles)
    return rejected("the model's meshes have " + count(model_triangles_) +
                    " triangles with " + file + "; at most " + count(limits_.model_triangles) +
                    " are accepted per model");
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->file = file;
  mesh->vertices.reserve(raw->vertices.size());
  for (const Vec3& v : raw->vertices) {
    const Vec3 p{scale.x * v.x, scale.y * v.y, scale.z * v.z};
    if (mesh->vertices.empty()) mesh->min = mesh->max = p;
    mesh->min = {std::min(mesh->min.x, p.x), std::min(mesh->min.y, p.y), std::min(mesh->min.z, p.z)};
    mesh->max = {std::max(mesh->max.x, p.x), std::max(mesh->max.y, p.y), std::max(mesh->max.z, p.z)};
    mesh->vertices.push_back(p);
  }
  // An odd number of negative scale factors mirrors the mesh: its triangles turn inside out.
  const bool mirrored = ((scale.x < 0) != (scale.y < 0)) != (scale.z < 0);
  mesh->triangles = raw->triangles;
  if (mirrored)
    for (auto& triangle : mesh->triangles) std::swap(triangle[1], triangle[2]);
  *out = std::move(mesh);
  return {};
}

}  // namespace core

Status readVisualMesh(const std::string& file, const Vec3& scale,
                      std::shared_ptr<const TriangleMesh>* out) {
  if (!std::isfinite(scale.x) || !std::isfinite(scale.y) || !std::isfinite(scale.z) ||
      scale.x == 0 || scale.y == 0 || scale.z == 0)
    return core::rejected("the mesh " + file + " has a zero or non-finite scale");
  // A visual mesh is drawn, never collided: far denser than a collision mesh may be.
  core::MeshReader::Limits limits;
  limits.file_bytes = 10 * core::kMaxMeshFileBytes;
  limits.mesh_triangles = limits.model_triangles = kMaxVisualMeshTriangles;
  limits.placements = core::kMaxMeshPlacements;
  limits.depth = core::kMaxMeshDepth;
  return core::MeshReader(limits).read(file, scale, out);
}

}  // namespace onedof_sim
