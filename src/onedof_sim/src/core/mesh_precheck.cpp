#include "mesh_precheck.h"

#include "expansion_graph.h"

#include <tinyxml2.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <vector>

namespace onedof_sim {
namespace core {
namespace {

using tinyxml2::XMLElement;

size_t add(size_t a, size_t b) { return saturatingAdd(a, b); }

bool named(const XMLElement& element, const char* name) {
  return std::strcmp(element.Name(), name) == 0;
}

// Whitespace-separated tokens of an element's text.
size_t tokens(const XMLElement* element) {
  const char* text = element ? element->GetText() : nullptr;
  size_t count = 0;
  for (bool in_token = false; text && *text; ++text) {
    const bool space = std::isspace(static_cast<unsigned char>(*text));
    if (!space && !in_token) ++count;
    in_token = !space;
  }
  return count;
}

// The triangles one COLLADA primitive element (<triangles>, <polylist>, ...) becomes after
// triangulation, from its index lists: each vertex takes `stride` indices (one per input
// offset). Lines and points are none.
size_t primitiveTriangles(const XMLElement& primitive) {
  size_t stride = 1;
  for (const XMLElement* input = primitive.FirstChildElement("input"); input;
       input = input->NextSiblingElement("input"))
    stride = std::max(stride, size_t(input->UnsignedAttribute("offset")) + 1);
  const auto polygon = [](size_t vertices) { return vertices >= 3 ? vertices - 2 : 0; };
  size_t triangles = 0;
  if (named(primitive, "triangles")) {
    for (const XMLElement* p = primitive.FirstChildElement("p"); p; p = p->NextSiblingElement("p"))
      triangles = add(triangles, tokens(p) / stride / 3);
  } else if (named(primitive, "polylist")) {
    const XMLElement* vcount = primitive.FirstChildElement("vcount");
    const char* text = vcount ? vcount->GetText() : nullptr;
    while (text && *text) {
      char* end = nullptr;
      const unsigned long long vertices = std::strtoull(text, &end, 10);
      if (end == text) break;
      triangles = add(triangles, polygon(size_t(std::min<unsigned long long>(vertices, std::numeric_limits<size_t>::max() / 4))));
      text = end;
    }
  } else if (named(primitive, "polygons") || named(primitive, "trifans") ||
             named(primitive, "tristrips")) {
    for (const XMLElement* e = primitive.FirstChildElement(); e; e = e->NextSiblingElement()) {
      if (named(*e, "p")) triangles = add(triangles, polygon(tokens(e) / stride));
      if (named(*e, "ph"))  // a polygon with holes: its outline
        triangles = add(triangles, polygon(tokens(e->FirstChildElement("p")) / stride));
    }
  }
  return triangles;
}

size_t geometryTriangles(const XMLElement& geometry) {
  size_t triangles = 0;
  for (const XMLElement* mesh = geometry.FirstChildElement("mesh"); mesh;
       mesh = mesh->NextSiblingElement("mesh"))
    for (const XMLElement* e = mesh->FirstChildElement(); e; e = e->NextSiblingElement())
      triangles = add(triangles, primitiveTriangles(*e));
  return triangles;
}

// The id a local URL ("#id") names; empty for another file's.
std::string localId(const XMLElement& instance) {
  const char* url = instance.Attribute("url");
  return url && url[0] == '#' ? std::string(url + 1) : std::string();
}

// A COLLADA document's nodes as an ExpansionGraph: each node's own counts are the triangles of
// the geometry it instances and its placements (itself and each geometry instance); its edges
// its child nodes and the nodes it instances.
class ColladaGraph {
 public:
  explicit ColladaGraph(const XMLElement& root) { collect(root); }

  MeshShape measure() const {
    const Expansion expansion = expand(graph_);
    MeshShape shape;
    if (!expansion.cycle.empty()) {
      shape.code = MeshShapeCode::InstanceCycle;
      for (size_t node : expansion.cycle)
        shape.subject += (shape.subject.empty() ? "" : " -> ") +
                         (ids_[node].empty() ? std::string("(a node without id)") : ids_[node]);
      return shape;
    }
    for (size_t root : roots_) {
      shape.triangles = add(shape.triangles, expansion.totals[root][0]);
      shape.placements = add(shape.placements, expansion.totals[root][1]);
      shape.depth = std::max(shape.depth, expansion.depth[root]);
    }
    return shape;
  }

 private:
  void collect(const XMLElement& root) {
    std::map<std::string, size_t> geometry_triangles;
    std::map<std::string, std::string> controller_geometry;  // a skin's or morph's source
    std::map<const XMLElement*, size_t> node_index;
    std::map<std::string, size_t> node_by_id;
    std::vector<const XMLElement*> node_elements, visual_scenes;
    const XMLElement* instanced_scene = nullptr;
    // The whole document, without recursion (tinyxml2 has bounded its depth already).
    std::vector<const XMLElement*> pending{&root};
    while (!pending.empty()) {
      const XMLElement* e = pending.back();
      pending.pop_back();
      const char* id = e->Attribute("id");
      if (named(*e, "geometry") && id) geometry_triangles[id] = geometryTriangles(*e);
      if (named(*e, "controller") && id)
        for (const char* kind : {"skin", "morph"})
          if (const XMLElement* source = e->FirstChildElement(kind))
            if (const char* url = source->Attribute("source"))
              if (url[0] == '#') controller_geometry[id] = url + 1;
      if (named(*e, "node")) {
        node_index[e] = node_elements.size();
        if (id) node_by_id.emplace(id, node_elements.size());
        node_elements.push_back(e);
      }
      if (named(*e, "visual_scene")) visual_scenes.push_back(e);
      if (named(*e, "instance_visual_scene") && e->Parent() && e->Parent()->ToElement() &&
          named(*e->Parent()->ToElement(), "scene"))
        instanced_scene = e;
      // Last child first onto the stack: the document is visited in its order.
      for (const XMLElement* child = e->LastChildElement(); child;
           child = child->PreviousSiblingElement())
        pending.push_back(child);
    }
    const auto triangles_of = [&](const std::string& geometry) {
      auto found = geometry_triangles.find(geometry);
      return found == geometry_triangles.end() ? size_t(0) : found->second;
    };
    const size_t count = node_elements.size();
    ids_.resize(count);
    graph_.edges.resize(count);
    graph_.own.assign(count, {0, 1});
    for (size_t i = 0; i < count; ++i) {
      const char* id = node_elements[i]->Attribute("id");
      ids_[i] = id ? id : "";
      std::vector<size_t>& edges = graph_.edges[i];
      std::array<size_t, 2>& own = graph_.own[i];
      for (const XMLElement* e = node_elements[i]->FirstChildElement(); e;
           e = e->NextSiblingElement()) {
        if (named(*e, "node")) {
          edges.push_back(node_index.at(e));
        } else if (named(*e, "instance_node")) {
          auto found = node_by_id.find(localId(*e));
          if (found != node_by_id.end()) edges.push_back(found->second);
        } else if (named(*e, "instance_geometry")) {
          own = {add(own[0], triangles_of(localId(*e))), add(own[1], 1)};
        } else if (named(*e, "instance_controller")) {
          auto source = controller_geometry.find(localId(*e));
          own = {add(own[0], source == controller_geometry.end() ? 0 : triangles_of(source->second)),
                 add(own[1], 1)};
        }
      }
    }
    // The scene <scene> instances, or the first visual scene: its top-level nodes.
    const XMLElement* scene = visual_scenes.empty() ? nullptr : visual_scenes.front();
    if (instanced_scene)
      for (const XMLElement* candidate : visual_scenes) {
        const char* id = candidate->Attribute("id");
        if (id && localId(*instanced_scene) == id) scene = candidate;
      }
    for (const XMLElement* e = scene ? scene->FirstChildElement("node") : nullptr; e;
         e = e->NextSiblingElement("node"))
      roots_.push_back(node_index.at(e));
  }

  ExpansionGraph graph_;
  std::vector<std::string> ids_;
  std::vector<size_t> roots_;
};

MeshShape measureCollada(const std::string& bytes, const MeshShapeLimits& limits) {
  tinyxml2::XMLDocument document;
  const tinyxml2::XMLError parsed = document.Parse(bytes.data(), bytes.size());
  MeshShape shape;
  if (parsed == tinyxml2::XML_ELEMENT_DEPTH_EXCEEDED) {
    shape.code = MeshShapeCode::TooDeep;
    shape.depth = size_t(TINYXML2_MAX_ELEMENT_DEPTH) + 1;
    shape.subject = "XML elements";
    return shape;
  }
  if (parsed != tinyxml2::XML_SUCCESS || !document.RootElement()) {
    shape.code = MeshShapeCode::NotWellFormed;
    shape.subject = document.ErrorStr() ? document.ErrorStr() : "no root element";
    return shape;
  }
  shape = ColladaGraph(*document.RootElement()).measure();
  if (shape.code != MeshShapeCode::Ok) return shape;
  if (shape.depth > limits.depth) {
    shape.code = MeshShapeCode::TooDeep;
    shape.subject = "nodes";
  }
  return shape;
}

// A line's first token is `word` (indented, when `indented`).
bool startsWith(const char* line, const char* end, const char* word, bool indented) {
  while (indented && line < end && (*line == ' ' || *line == '\t')) ++line;
  const size_t length = std::strlen(word);
  return size_t(end - line) > length && std::strncmp(line, word, length) == 0 &&
         std::isspace(static_cast<unsigned char>(line[length]));
}

// Calls f(begin, end) for each line of bytes.
template <class F>
void eachLine(const std::string& bytes, F f) {
  const char* p = bytes.data();
  const char* const end = p + bytes.size();
  while (p < end) {
    const char* line_end = static_cast<const char*>(std::memchr(p, '\n', size_t(end - p)));
    if (!line_end) line_end = end;
    f(p, line_end < end ? line_end + 1 : end);
    p = line_end + 1;
  }
}

// STL as assimp tells the two kinds apart: binary when its size is the 84-byte header and 50
// bytes per triangle the header counts; else ASCII, a triangle per `facet`.
MeshShape measureStl(const std::string& bytes) {
  MeshShape shape;
  shape.placements = shape.depth = 1;
  if (bytes.size() >= 84) {
    uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, 4);
    if (84 + 50 * uint64_t(count) == bytes.size()) {
      shape.triangles = count;
      return shape;
    }
  }
  eachLine(bytes, [&](const char* line, const char* end) {
    if (startsWith(line, end, "facet", true)) ++shape.triangles;
  });
  return shape;
}

// OBJ: each face `f v1 v2 ... vn` becomes n - 2 triangles; lines and points are none. assimp
// reads a face only at the start of its line.
MeshShape measureObj(const std::string& bytes) {
  MeshShape shape;
  shape.placements = shape.depth = 1;
  eachLine(bytes, [&](const char* line, const char* end) {
    if (!startsWith(line, end, "f", false)) return;
    size_t vertices = 0;
    bool in_token = false;
    for (const char* p = line; p < end && *p != '#'; ++p) {
      const bool space = std::isspace(static_cast<unsigned char>(*p));
      if (!space && !in_token) ++vertices;
      in_token = !space;
    }
    if (vertices >= 4) shape.triangles += vertices - 3;  // the `f` is a token too
  });
  return shape;
}

}  // namespace

MeshFormat meshFormatOf(const std::string& file) {
  std::string extension = std::filesystem::path(file).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  if (extension == ".stl") return MeshFormat::Stl;
  if (extension == ".dae") return MeshFormat::Collada;
  if (extension == ".obj") return MeshFormat::Obj;
  return MeshFormat::Unknown;
}

const char* meshFormatExtension(MeshFormat format) {
  switch (format) {
    case MeshFormat::Stl: return "stl";
    case MeshFormat::Collada: return "dae";
    case MeshFormat::Obj: return "obj";
    case MeshFormat::Unknown: break;
  }
  return "";
}

MeshShape measureMesh(const std::string& bytes, MeshFormat format, const MeshShapeLimits& limits) {
  MeshShape shape = format == MeshFormat::Collada ? measureCollada(bytes, limits)
                    : format == MeshFormat::Stl   ? measureStl(bytes)
                                                  : measureObj(bytes);
  if (shape.code != MeshShapeCode::Ok) return shape;
  if (shape.placements > limits.placements) shape.code = MeshShapeCode::TooManyPlacements;
  else if (shape.triangles > limits.triangles) shape.code = MeshShapeCode::TooManyTriangles;
  return shape;
}

}  // namespace core
}  // namespace onedof_sim
