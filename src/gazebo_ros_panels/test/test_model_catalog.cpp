// The Insert tab's catalog: model.config's name, the highest SDF version, the first of two
// folders of one name, folders that are not models left out, the path's order and the shapes.
#include <gtest/gtest.h>

#include <filesystem>
#include <unistd.h>

#include <fstream>

#include "model_catalog.h"

namespace fs = std::filesystem;
using gazebo_ros_panels::CatalogModel;
using gazebo_ros_panels::listModels;
using gazebo_ros_panels::modelPathFolders;
using gazebo_ros_panels::shapeSdf;

namespace {

class Folder {
 public:
  Folder() {
    path_ = fs::temp_directory_path() / ("catalog_" + std::to_string(::getpid()) + "_" +
                                         std::to_string(counter_++));
    fs::create_directories(path_);
  }
  ~Folder() { fs::remove_all(path_); }
  std::string path() const { return path_.string(); }
  void write(const std::string& relative, const std::string& text) const {
    fs::create_directories((path_ / relative).parent_path());
    std::ofstream(path_ / relative) << text;
  }

 private:
  static int counter_;
  fs::path path_;
};
int Folder::counter_ = 0;

const CatalogModel* find(const std::vector<CatalogModel>& models, const std::string& uri_name) {
  for (const CatalogModel& model : models)
    if (model.uri_name == uri_name) return &model;
  return nullptr;
}

}  // namespace

TEST(ModelCatalog, ListsModelsByTheirConfigNameAfterTheShapes) {
  Folder path;
  path.write("cafe_table/model.config",
             "<model><name>Cafe table</name><sdf version='1.6'>model.sdf</sdf></model>");
  path.write("cafe_table/model.sdf", "<sdf/>");
  path.write("anonymous/model.config", "<model><sdf version='1.6'>m.sdf</sdf></model>");
  path.write("anonymous/m.sdf", "<sdf/>");
  const std::vector<CatalogModel> models = listModels({path.path()});
  ASSERT_EQ(models.size(), 5u);
  EXPECT_EQ(models[0].uri_name, "unit_box");
  EXPECT_EQ(models[1].uri_name, "unit_sphere");
  EXPECT_EQ(models[2].uri_name, "unit_cylinder");
  EXPECT_EQ(models[3].name, "Cafe table");  // sorted by shown name: "Cafe table" < "anonymous"
  EXPECT_EQ(models[3].uri_name, "cafe_table");
  EXPECT_EQ(models[3].sdf_path, path.path() + "/cafe_table/model.sdf");
  EXPECT_EQ(models[4].name, "anonymous");
}

TEST(ModelCatalog, TakesTheHighestSdfVersion) {
  Folder path;
  path.write("m/model.config",
             "<model><name>M</name><sdf version='1.4'>old.sdf</sdf>"
             "<sdf version='1.10'>newest.sdf</sdf><sdf version='1.9'>new.sdf</sdf></model>");
  for (const char* file : {"m/old.sdf", "m/new.sdf", "m/newest.sdf"}) path.write(file, "<sdf/>");
  const std::vector<CatalogModel> models = listModels({path.path()});
  const CatalogModel* model = find(models, "m");
  ASSERT_NE(model, nullptr);
  EXPECT_EQ(model->sdf_path, path.path() + "/m/newest.sdf");
}

TEST(ModelCatalog, LeavesOutFoldersThatAreNotModels) {
  Folder path;
  path.write("no_config/model.sdf", "<sdf/>");
  path.write("malformed/model.config", "<model><name>x</name");
  path.write("missing_sdf/model.config", "<model><sdf version='1.6'>gone.sdf</sdf></model>");
  path.write("plain_file", "x");
  EXPECT_EQ(listModels({path.path(), "/no/such/folder"}).size(), 3u);  // the shapes alone
}

TEST(ModelCatalog, TheFirstFolderOfANameOnThePathIsTheModel) {
  Folder first, second;
  first.write("table/model.config", "<model><name>First</name><sdf>model.sdf</sdf></model>");
  first.write("table/model.sdf", "<sdf/>");
  second.write("table/model.config", "<model><name>Second</name><sdf>model.sdf</sdf></model>");
  second.write("table/model.sdf", "<sdf/>");
  second.write("chair/model.config", "<model><name>Chair</name><sdf>model.sdf</sdf></model>");
  second.write("chair/model.sdf", "<sdf/>");
  const std::vector<CatalogModel> models = listModels({first.path(), second.path()});
  ASSERT_EQ(models.size(), 5u);
  EXPECT_EQ(find(models, "table")->name, "First");
  EXPECT_NE(find(models, "chair"), nullptr);
}

TEST(ModelCatalog, ModelPathIsTheSimulatorsThenGazeboModelPathThenExportsEachOnce) {
  EXPECT_EQ(modelPathFolders({"/sim/models", "/a"}, "/a::/b:/sim/models", {"/c", "/b"}),
            (std::vector<std::string>{"/sim/models", "/a", "/b", "/c"}));
  EXPECT_TRUE(modelPathFolders({}, "", {}).empty());
}

TEST(ModelCatalog, ShapesRestOnTheGroundAtZeroAndUnknownShapesHaveNoSdf) {
  for (const char* shape : {"box", "sphere", "cylinder"}) {
    const std::string sdf = shapeSdf(shape);
    EXPECT_NE(sdf.find(std::string("<model name=\"unit_") + shape + "\">"), std::string::npos);
    EXPECT_NE(sdf.find("<pose>0 0 0.5 0 0 0</pose>"), std::string::npos) << shape;
    EXPECT_NE(sdf.find("<mass>1</mass>"), std::string::npos) << shape;
  }
  EXPECT_NE(shapeSdf("box").find("<size>1 1 1</size>"), std::string::npos);
  EXPECT_EQ(shapeSdf("cone"), "");
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
