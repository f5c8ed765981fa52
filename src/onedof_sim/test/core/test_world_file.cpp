// World files read by the core (onedof_sim/world_file.h), no ROS: the physics each engine gets,
// what a field the file does not set keeps, includes with their overrides, what is ignored, and
// the codes of a world that cannot be read.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "onedof_sim/world.h"
#include "onedof_sim/world_file.h"

namespace onedof_sim {
namespace {

const std::vector<std::string> kModelPath{ONEDOF_SOURCE_DIR "/src/onedof_sim/models"};

class WorldFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::temp_directory_path() /
              ("onedof_world_file_" + std::to_string(::getpid()));
    std::filesystem::create_directories(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  std::string write(const std::string& text) {
    const std::string path = (folder_ / "test.world").string();
    std::ofstream(path) << text;
    return path;
  }

  WorldFileStatus read(const std::string& world_content, WorldFile* out,
                       const PhysicsParams& base = PhysicsParams()) {
    return readWorldFile(write("<sdf version=\"1.6\"><world name=\"w\">" + world_content +
                               "</world></sdf>"),
                         kModelPath, base, out);
  }

  std::filesystem::path folder_;
};

TEST_F(WorldFileTest, EachEngineGetsTheCommonPhysicsAndItsOwnBlock) {
  WorldFile world;
  const WorldFileStatus status = read(
      "<gravity>0 0 -3</gravity>"
      "<physics type=\"bullet\"><max_step_size>0.004</max_step_size>"
      "<real_time_update_rate>250</real_time_update_rate><max_contacts>7</max_contacts>"
      "<ode><solver><type>world</type><iters>33</iters><sor>1.1</sor></solver>"
      "<constraints><erp>0.5</erp><cfm>0.01</cfm></constraints></ode>"
      "<bullet><solver><iters>77</iters></solver><constraints><erp>0.3</erp></constraints>"
      "</bullet></physics>",
      &world);
  ASSERT_TRUE(status.ok()) << status.subject;
  EXPECT_EQ(world.name, "w");
  EXPECT_EQ(world.physics_type, "bullet");
  ASSERT_TRUE(world.real_time_update_rate.has_value());
  EXPECT_EQ(*world.real_time_update_rate, 250);
  for (const std::string& engine : World::engineNames()) {
    ASSERT_EQ(world.physics.count(engine), 1u) << engine;
    const PhysicsParams& p = world.physics.at(engine);
    EXPECT_EQ(p.step, 0.004) << engine;
    EXPECT_EQ(p.gravity.z, -3) << engine;
    EXPECT_EQ(p.max_contacts, 7u) << engine;
  }
  const PhysicsParams& ode = world.physics.at("ode");
  EXPECT_FALSE(ode.quick_step);
  EXPECT_EQ(ode.sor_pgs_iters, 33u);
  EXPECT_EQ(ode.sor_pgs_w, 1.1);
  EXPECT_EQ(ode.erp, 0.5);
  EXPECT_EQ(ode.cfm, 0.01);
  const PhysicsParams& bullet = world.physics.at("bullet");
  EXPECT_EQ(bullet.sor_pgs_iters, 77u);
  EXPECT_EQ(bullet.erp, 0.3);
  EXPECT_EQ(bullet.cfm, PhysicsParams().cfm);
}

TEST_F(WorldFileTest, WhatTheFileDoesNotSetKeepsTheBase) {
  PhysicsParams base;
  base.step = 0.005;
  base.gravity = {0, 0, -1};
  base.quick_step = false;
  WorldFile world;
  // libsdformat fills in <physics>'s required elements (max_step_size, gravity, solver type
  // quick) with SDF's defaults: they are not the file's.
  ASSERT_TRUE(read("<physics type=\"ode\"><ode><constraints><erp>0.4</erp></constraints></ode>"
                   "</physics>",
                   &world, base)
                  .ok());
  const PhysicsParams& ode = world.physics.at("ode");
  EXPECT_EQ(ode.step, 0.005);
  EXPECT_EQ(ode.gravity.z, -1);
  EXPECT_FALSE(ode.quick_step);
  EXPECT_EQ(ode.erp, 0.4);
  EXPECT_FALSE(world.real_time_update_rate.has_value());

  WorldFile bare;
  ASSERT_TRUE(read("", &bare, base).ok());
  EXPECT_EQ(bare.physics_type, "");
  EXPECT_EQ(bare.physics.at("ode").step, 0.005);
  EXPECT_TRUE(bare.models.empty() && bare.ignored.empty());
}

TEST_F(WorldFileTest, IncludesTakeTheIncludesNamePoseAndStaticAndSpawn) {
  WorldFile file;
  const WorldFileStatus status = read(
      "<include><uri>model://sun</uri></include>"
      "<include><uri>model://cafe_table</uri><pose>1 2 0 0 0 0</pose></include>"
      "<include><uri>model://toy_block</uri><name>held</name><static>true</static>"
      "<pose>0 0 2 0 0 0</pose></include>",
      &file);
  ASSERT_TRUE(status.ok()) << status.subject;
  ASSERT_EQ(file.models.size(), 2u);  // the sun is a light
  EXPECT_EQ(file.models[0].name, "cafe_table");
  EXPECT_EQ(file.models[0].pose.position.x, 1);
  EXPECT_EQ(file.models[0].pose.position.y, 2);
  EXPECT_EQ(file.models[1].name, "held");
  EXPECT_EQ(file.models[1].pose.position.z, 2);
  ASSERT_EQ(file.ignored.size(), 1u);
  EXPECT_EQ(file.ignored[0].element, "light");
  EXPECT_EQ(file.ignored[0].name, "sun");

  for (const std::string& engine : World::engineNames()) {
    World world(engine);
    world.setModelPath(kModelPath);
    for (const WorldFileModel& model : file.models)
      ASSERT_TRUE(world.spawn(model.name, model.sdf, ModelFormat::Sdf, model.pose).ok())
          << engine << " " << model.name << "\n" << model.sdf;
    ModelInfo held;
    ASSERT_TRUE(world.modelProperties("held", &held).ok());
    EXPECT_TRUE(held.is_static) << engine;
    for (int i = 0; i < 100; ++i) world.step();
    Pose pose;
    Twist twist;
    ASSERT_TRUE(world.modelState("held", "", &pose, &twist).ok());
    EXPECT_EQ(pose.position.z, 2) << engine;
  }
}

TEST_F(WorldFileTest, PluginsSceneAndOtherElementsAreListedAsIgnored) {
  WorldFile world;
  ASSERT_TRUE(read("<scene><ambient>0.4 0.4 0.4 1</ambient></scene>"
                   "<plugin name=\"ticker\" filename=\"libticker.so\"/>",
                   &world)
                  .ok());
  ASSERT_EQ(world.ignored.size(), 2u);
  EXPECT_EQ(world.ignored[0].element, "scene");
  EXPECT_EQ(world.ignored[1].element, "plugin");
  EXPECT_EQ(world.ignored[1].name, "ticker");
  EXPECT_EQ(world.ignored[1].filename, "libticker.so");
}

TEST_F(WorldFileTest, AWorldThatCannotBeReadSaysWhy) {
  WorldFile world;
  EXPECT_EQ(readWorldFile((folder_ / "none.world").string(), kModelPath, {}, &world).code,
            WorldFileCode::NotFound);
  WorldFileStatus status = read("<include><uri>model://nope</uri></include>", &world);
  EXPECT_EQ(status.code, WorldFileCode::IncludeNotFound);
  EXPECT_EQ(status.subject, "model://nope");
  status = readWorldFile(write("<sdf version=\"1.6\"><world name=\"w\"></sdf>"), kModelPath, {},
                         &world);
  EXPECT_EQ(status.code, WorldFileCode::InvalidXml);
  EXPECT_NE(status.subject.find("Line number=1"), std::string::npos) << status.subject;
  status = readWorldFile(write("<sdf version=\"1.6\"><model name=\"m\"><link name=\"l\"/>"
                               "</model></sdf>"),
                         kModelPath, {}, &world);
  EXPECT_EQ(status.code, WorldFileCode::NoWorld);
  status = read("<physics type=\"ode\"><ode><solver><iters>-3</iters></solver></ode></physics>",
                &world);
  EXPECT_EQ(status.code, WorldFileCode::NegativeCount);
  EXPECT_EQ(status.subject, "iters");
  status = read("<model name=\"a\"><link name=\"l\"/></model><model name=\"a\"><link "
                "name=\"l\"/></model>",
                &world);
  EXPECT_EQ(status.code, WorldFileCode::InvalidSdf) << status.subject;
}

// Models and includes count alike.
TEST_F(WorldFileTest, AWorldOfMoreModelsThanTheLimitIsRefused) {
  std::string models;
  for (int i = 0; i < 1000; ++i)
    models += "<model name=\"m" + std::to_string(i) + "\"><link name=\"l\"/></model>";
  for (const std::string& last :
       {std::string("<model name=\"m1000\"><link name=\"l\"/></model>"),
        std::string("<include><uri>model://toy_block</uri></include>")}) {
    WorldFile world;
    const WorldFileStatus status = read(models + last, &world);
    EXPECT_EQ(status.code, WorldFileCode::TooManyModels) << last;
    EXPECT_EQ(status.subject, "1001");
    EXPECT_EQ(status.max, 1000);
  }
}

}  // namespace
}  // namespace onedof_sim
