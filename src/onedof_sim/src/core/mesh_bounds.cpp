#include "mesh_bounds.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

namespace onedof_sim {
namespace core {
namespace {

std::string lowercaseExtension(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || path.find('/', dot) != std::string::npos) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

class BoundsBuilder {
 public:
  void add(double x, double y, double z) {
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
      non_finite_ = true;
      return;
    }
    if (count_++ == 0) {
      bounds_.min = bounds_.max = {x, y, z};
      return;
    }
    bounds_.min = {std::min(bounds_.min.x, x), std::min(bounds_.min.y, y),
                   std::min(bounds_.min.z, z)};
    bounds_.max = {std::max(bounds_.max.x, x), std::max(bounds_.max.y, y),
                   std::max(bounds_.max.z, z)};
  }
  bool finish(const std::string& path, MeshBounds* bounds, std::string* error) const {
    if (non_finite_) {
      *error = "mesh file " + path + " has a non-finite vertex";
      return false;
    }
    if (count_ == 0) {
      *error = "mesh file " + path + " has no vertices";
      return false;
    }
    *bounds = bounds_;
    return true;
  }

 private:
  MeshBounds bounds_;
  size_t count_ = 0;
  bool non_finite_ = false;
};

// Lines "KEYWORD x y z" (STL's `vertex`, OBJ's `v`).
void addKeywordVertices(const std::string& text, const std::string& keyword,
                        BoundsBuilder* builder) {
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string first;
    double x, y, z;
    if (words >> first && first == keyword && words >> x >> y >> z) builder->add(x, y, z);
  }
}

// A binary STL is an 80-byte header, a little-endian triangle count, then 50 bytes a triangle
// (normal, three vertices as float32, attribute word); its size says which kind a file is, since
// binary files may also begin with "solid".
bool isBinaryStl(const std::string& data) {
  if (data.size() < 84) return false;
  uint32_t triangles;
  std::memcpy(&triangles, data.data() + 80, 4);
  return data.size() == 84 + 50 * static_cast<uint64_t>(triangles);
}

void addBinaryStlVertices(const std::string& data, BoundsBuilder* builder) {
  uint32_t triangles;
  std::memcpy(&triangles, data.data() + 80, 4);
  for (uint32_t t = 0; t < triangles; ++t) {
    const char* triangle = data.data() + 84 + 50 * static_cast<size_t>(t);
    for (int v = 1; v <= 3; ++v) {
      float xyz[3];
      std::memcpy(xyz, triangle + 12 * v, sizeof xyz);
      builder->add(xyz[0], xyz[1], xyz[2]);
    }
  }
}

}  // namespace

bool readMeshBounds(const std::string& path, MeshBounds* bounds, std::string* error) {
  const std::string ext = lowercaseExtension(path);
  if (ext != "stl" && ext != "obj") {
    *error = "only STL and OBJ meshes are read for collisions (as their bounding box), not " +
             path;
    return false;
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    *error = "cannot read mesh file " + path;
    return false;
  }
  const std::string data((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  BoundsBuilder builder;
  if (ext == "obj")
    addKeywordVertices(data, "v", &builder);
  else if (isBinaryStl(data))
    addBinaryStlVertices(data, &builder);
  else
    addKeywordVertices(data, "vertex", &builder);
  return builder.finish(path, bounds, error);
}

}  // namespace core
}  // namespace onedof_sim
