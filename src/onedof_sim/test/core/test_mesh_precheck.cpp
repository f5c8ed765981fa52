// The measure of a mesh file's structure before assimp reads it (src/core/mesh_precheck.h):
// COLLADA files nested past the limit, instancing themselves, fanning one triangle out to
// millions, refused by the measure alone; its counts agree with what assimp reads from files
// within the limits; and a world refuses such meshes with a reason, its models intact.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "mesh_loader.h"
#include "mesh_precheck.h"
#include "model_description.h"
#include "onedof_sim/world.h"

namespace onedof_sim {
namespace core {
namespace {

const MeshShapeLimits kLimits{kMaxMeshTriangles, kMaxMeshPlacements, kMaxMeshDepth};

// One triangle as geometry "g".
const char* const kTriangleGeometry =
    "<library_geometries><geometry id=\"g\"><mesh>"
    "<source id=\"p\"><float_array id=\"pa\" count=\"9\">0 0 0 1 0 0 0 1 0</float_array>"
    "<technique_common><accessor source=\"#pa\" count=\"3\" stride=\"3\">"
    "<param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/>"
    "<param name=\"Z\" type=\"float\"/></accessor></technique_common></source>"
    "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>"
    "<triangles count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
    "<p>0 1 2</p></triangles></mesh></geometry></library_geometries>";

// A COLLADA document: the triangle geometry, `library` (<library_nodes> content) and `scene`
// (the visual scene's content).
std::string collada(const std::string& library, const std::string& scene) {
  return std::string("<?xml version=\"1.0\"?><COLLADA "
                     "xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">"
                     "<asset><unit meter=\"1\"/><up_axis>Z_UP</up_axis></asset>") +
         kTriangleGeometry + "<library_nodes>" + library +
         "</library_nodes><library_visual_scenes><visual_scene id=\"s\">" + scene +
         "</visual_scene></library_visual_scenes><scene><instance_visual_scene url=\"#s\"/>"
         "</scene></COLLADA>";
}

// `levels` <node>s nested in one another, the innermost placing the triangle.
std::string nestedNodes(int levels) {
  std::string open, close;
  for (int i = 0; i < levels; ++i) {
    open += "<node>";
    close += "</node>";
  }
  return collada("", open + "<instance_geometry url=\"#g\"/>" + close);
}

// Node level0 places `fan` instances of level1, ..., level<levels-1> places `fan` triangles:
// fan^levels triangles from a file of a few kB.
std::string fanOut(int levels, int fan) {
  std::string library;
  for (int level = 0; level < levels; ++level) {
    library += "<node id=\"level" + std::to_string(level) + "\">";
    for (int i = 0; i < fan; ++i)
      library += level + 1 < levels ? "<instance_node url=\"#level" + std::to_string(level + 1) +
                                          "\"/>"
                                    : std::string("<instance_geometry url=\"#g\"/>");
    library += "</node>";
  }
  return collada(library, "<node><instance_node url=\"#level0\"/></node>");
}

TEST(MeshPrecheck, NestedNodesPastTheXmlDepthAreRefused) {
  const MeshShape deep = measureMesh(nestedNodes(10000), MeshFormat::Collada, kLimits);
  EXPECT_EQ(deep.code, MeshShapeCode::TooDeep);
  EXPECT_EQ(deep.subject, "XML elements");
  const MeshShape shallow = measureMesh(nestedNodes(50), MeshFormat::Collada, kLimits);
  EXPECT_EQ(shallow.code, MeshShapeCode::Ok) << shallow.subject;
  EXPECT_EQ(shallow.depth, 50u);
  EXPECT_EQ(shallow.triangles, 1u);
  EXPECT_EQ(shallow.placements, 51u);  // 50 nodes and the geometry instance
}

TEST(MeshPrecheck, AChainOfInstancesPastTheDepthIsRefused) {
  std::string library;
  for (int i = 0; i < 300; ++i)
    library += "<node id=\"n" + std::to_string(i) + "\">" +
               (i + 1 < 300 ? "<instance_node url=\"#n" + std::to_string(i + 1) + "\"/>"
                            : std::string("<instance_geometry url=\"#g\"/>")) +
               "</node>";
  const MeshShape chain = measureMesh(
      collada(library, "<node><instance_node url=\"#n0\"/></node>"), MeshFormat::Collada, kLimits);
  EXPECT_EQ(chain.code, MeshShapeCode::TooDeep);
  EXPECT_EQ(chain.subject, "nodes");
  EXPECT_EQ(chain.depth, 301u);
}

TEST(MeshPrecheck, NodesInstancingThemselvesAreRefusedNamingTheCycle) {
  const std::string loop = collada(
      "<node id=\"loop\"><instance_geometry url=\"#g\"/><instance_node url=\"#loop\"/></node>",
      "<node><instance_node url=\"#loop\"/></node>");
  MeshShape shape = measureMesh(loop, MeshFormat::Collada, kLimits);
  EXPECT_EQ(shape.code, MeshShapeCode::InstanceCycle);
  EXPECT_EQ(shape.subject, "loop -> loop");
  const std::string mutual = collada(
      "<node id=\"a\"><instance_node url=\"#b\"/></node>"
      "<node id=\"b\"><node><instance_node url=\"#a\"/></node></node>",
      "<node><instance_node url=\"#a\"/></node>");
  shape = measureMesh(mutual, MeshFormat::Collada, kLimits);
  EXPECT_EQ(shape.code, MeshShapeCode::InstanceCycle);
  EXPECT_EQ(shape.subject, "a -> b -> (a node without id) -> a");
}

// One triangle instanced 4^10 times: refused from the counts, in a few kB of memory; 4^40
// saturates without overflowing.
TEST(MeshPrecheck, FanOutIsCountedBeforeAnythingIsPlaced) {
  MeshShape shape = measureMesh(fanOut(10, 4), MeshFormat::Collada, kLimits);
  EXPECT_EQ(shape.code, MeshShapeCode::TooManyPlacements);
  EXPECT_EQ(shape.triangles, 1048576u);
  MeshShapeLimits many_placements = kLimits;
  many_placements.placements = 100000000;
  shape = measureMesh(fanOut(10, 4), MeshFormat::Collada, many_placements);
  EXPECT_EQ(shape.code, MeshShapeCode::TooManyTriangles);
  EXPECT_EQ(shape.triangles, 1048576u);
  shape = measureMesh(fanOut(40, 4), MeshFormat::Collada, kLimits);
  EXPECT_EQ(shape.code, MeshShapeCode::TooManyPlacements);
  EXPECT_GT(shape.triangles, size_t(1) << 60);
  shape = measureMesh(fanOut(3, 4), MeshFormat::Collada, kLimits);
  EXPECT_EQ(shape.code, MeshShapeCode::Ok);
  EXPECT_EQ(shape.triangles, 64u);
}

// A folder of mesh files in a fresh temporary folder.
class TempFolder {
 public:
  TempFolder() {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "onedof_precheck_XXXXXX").string();
    root_ = mkdtemp(pattern.data());
  }
  ~TempFolder() { std::filesystem::remove_all(root_); }
  std::string write(const std::string& name, const std::string& data) const {
    const std::string path = root_ + "/" + name;
    std::ofstream(path, std::ios::binary) << data;
    return path;
  }

 private:
  std::string root_;
};

size_t assimpTriangles(const std::string& file) {
  MeshReader reader;
  std::shared_ptr<const TriangleMesh> mesh;
  const Status status = reader.read(file, {1, 1, 1}, &mesh);
  EXPECT_TRUE(status.ok()) << status;
  return mesh ? mesh->triangles.size() : 0;
}

// The measure counts what assimp places: triangles, a polylist's quads and a pentagon, a
// polygon, a strip and a fan, lines (none), each geometry placed by an instanced node twice.
TEST(MeshPrecheck, CountsAgreeWithWhatAssimpReads) {
  TempFolder folder;
  const std::string shapes =
      "<library_geometries><geometry id=\"q\"><mesh>"
      "<source id=\"p\"><float_array id=\"pa\" count=\"18\">0 0 0 1 0 0 1 1 0 0 1 0 0.5 1.5 0 "
      "0 0 1</float_array><technique_common><accessor source=\"#pa\" count=\"6\" stride=\"3\">"
      "<param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/>"
      "<param name=\"Z\" type=\"float\"/></accessor></technique_common></source>"
      "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>"
      "<triangles count=\"2\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
      "<p>0 1 2 0 2 3</p></triangles>"
      "<polylist count=\"2\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
      "<vcount>4 5</vcount><p>0 1 2 3 0 1 2 4 3</p></polylist>"
      "<polygons count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
      "<p>0 1 5</p></polygons>"
      "<tristrips count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
      "<p>0 1 3 2</p></tristrips>"
      "<trifans count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
      "<p>0 1 2 3</p></trifans>"
      "<lines count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
      "<p>0 5</p></lines></mesh></geometry></library_geometries>";
  std::string document = collada(
      "<node id=\"part\"><instance_geometry url=\"#q\"/></node>",
      "<node><instance_node url=\"#part\"/></node><node><instance_node url=\"#part\"/></node>");
  document.replace(document.find("<library_geometries>"),
                   document.find("</library_geometries>") + 21 - document.find("<library_geometries>"),
                   shapes);
  const std::string dae = folder.write("shapes.dae", document);
  const MeshShape shape = measureMesh(document, MeshFormat::Collada, kLimits);
  ASSERT_EQ(shape.code, MeshShapeCode::Ok) << shape.subject;
  // 2 + (2 + 3) + 1 + 2 + 2 = 12 a placement.
  EXPECT_EQ(shape.triangles, 24u);
  EXPECT_EQ(assimpTriangles(dae), shape.triangles);

  const std::string obj_text =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
      "f 1 2 3\nf 1 2 3 4\n# a pentagon, and a face indented, which assimp skips\nf 1 2 3 4 5\n"
      "  f 1 2 3\nl 1 5\n";
  const std::string obj = folder.write("shapes.obj", obj_text);
  EXPECT_EQ(measureMesh(obj_text, MeshFormat::Obj, kLimits).triangles, 6u);
  EXPECT_EQ(assimpTriangles(obj), 6u);

  std::string stl_text = "solid s\n";
  for (int i = 0; i < 3; ++i)
    stl_text += " facet normal 0 0 1\n  outer loop\n   vertex 0 0 " + std::to_string(i) +
                "\n   vertex 1 0 " + std::to_string(i) + "\n   vertex 0 1 " + std::to_string(i) +
                "\n  endloop\n endfacet\n";
  stl_text += "endsolid s\n";
  const std::string stl = folder.write("three.stl", stl_text);
  EXPECT_EQ(measureMesh(stl_text, MeshFormat::Stl, kLimits).triangles, 3u);
  EXPECT_EQ(assimpTriangles(stl), 3u);
}

TEST(MeshPrecheck, FormatsAreTheThreeGazeboReads) {
  EXPECT_EQ(meshFormatOf("/a/b.STL"), MeshFormat::Stl);
  EXPECT_EQ(meshFormatOf("b.Dae"), MeshFormat::Collada);
  EXPECT_EQ(meshFormatOf("b.obj"), MeshFormat::Obj);
  EXPECT_EQ(meshFormatOf("b.ply"), MeshFormat::Unknown);
  EXPECT_EQ(meshFormatOf("dae"), MeshFormat::Unknown);
}

std::string staticMeshUrdf(const std::string& uri) {
  return "<robot name=\"floor\"><link name=\"world\"/><joint name=\"glue\" type=\"fixed\">"
         "<parent link=\"world\"/><child link=\"floor\"/></joint><link name=\"floor\">"
         "<collision><geometry><mesh filename=\"" + uri +
         "\"/></geometry></collision></link></robot>";
}

// Each hostile file refused with its reason on every engine, the world's models intact.
class HostileMeshes : public ::testing::TestWithParam<std::string> {};

TEST_P(HostileMeshes, AreRefusedWithTheReasonTheWorldIntact) {
  TempFolder folder;
  World world(GetParam());
  const std::string good = folder.write("good.dae", fanOut(2, 2));
  ASSERT_TRUE(world.spawn("good", staticMeshUrdf(good), ModelFormat::Urdf, Pose()).ok());
  const struct {
    const char* name;
    std::string data;
    std::string reason;
  } cases[] = {
      {"nested.dae", nestedNodes(10000),
       "nests its XML elements more than 100 deep; at most 100 levels are accepted"},
      {"loop.dae",
       collada("<node id=\"loop\"><instance_geometry url=\"#g\"/><instance_node url=\"#loop\"/>"
               "</node>",
               "<node><instance_node url=\"#loop\"/></node>"),
       "has a node that instances itself: loop -> loop"},
      {"fan.dae", fanOut(10, 4),
       "places 1398102 nodes and geometry instances; at most 20000 are accepted"},
      {"cube.ply", "ply\nformat ascii 1.0\nend_header\n",
       "is not STL (.stl), COLLADA (.dae) or OBJ (.obj)"},
  };
  for (const auto& c : cases) {
    const std::string file = folder.write(c.name, c.data);
    const Status status = world.spawn("hostile", staticMeshUrdf(file), ModelFormat::Urdf, Pose());
    EXPECT_EQ(status.code, StatusCode::ModelRejected) << c.name;
    EXPECT_NE(status.subject.find("the mesh file " + file + " " + c.reason), std::string::npos)
        << status;
  }
  // The extension picks assimp's importer: a deep COLLADA document named .stl or .obj is read as
  // that format, never as COLLADA, and refused for what it is not.
  for (const char* name : {"nested_as.stl", "nested_as.obj"}) {
    const std::string file = folder.write(name, nestedNodes(10000));
    const Status status = world.spawn("hostile", staticMeshUrdf(file), ModelFormat::Urdf, Pose());
    EXPECT_EQ(status.code, StatusCode::ModelRejected) << name;
  }
  EXPECT_EQ(world.modelNames(), std::vector<std::string>{"good"});
  EXPECT_TRUE(world.step().ok());
}

INSTANTIATE_TEST_SUITE_P(Engines, HostileMeshes, ::testing::ValuesIn(World::engineNames()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace core
}  // namespace onedof_sim
