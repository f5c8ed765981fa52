// World files read by the core (onedof_sim/world_file.h), no ROS: the physics each engine gets,
// what a field the file does not set keeps, includes with their overrides, what is ignored, and
// the codes of a world that cannot be read.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
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
  status = readWorldFile(write("<gazebo version=\"1.0\"><world name=\"w\"/></gazebo>"),
                         kModelPath, {}, &world);
  EXPECT_EQ(status.code, WorldFileCode::NotSdf);
  EXPECT_EQ(status.subject, "<gazebo version=\"1.0\">");
  status = read("<state world_name=\"w\"><sim_time>-3 0</sim_time></state>", &world);
  EXPECT_EQ(status.code, WorldFileCode::InvalidState);
  EXPECT_EQ(status.subject, "<sim_time> -3 0");
}

// A world saved by Gazebo 11 (tests/worlds/gazebo11_saved.world): its <plane> ground, <script>
// materials, lights, GUI camera, scene, wind, atmosphere and the like load; its <state> puts each
// model where it says and gives the clock; on every engine the models spawn and the box, placed by
// the state, rests on the ground plane.
TEST_F(WorldFileTest, AWorldSavedByGazeboLoadsWithItsStateApplied) {
  WorldFile file;
  const WorldFileStatus status = readWorldFile(
      ONEDOF_SOURCE_DIR "/tests/worlds/gazebo11_saved.world", kModelPath, {}, &file);
  ASSERT_TRUE(status.ok()) << status.subject;
  EXPECT_EQ(file.name, "default");
  EXPECT_EQ(file.physics_type, "ode");
  std::vector<std::string> names;
  for (const WorldFileModel& model : file.models) names.push_back(model.name);
  EXPECT_EQ(names, (std::vector<std::string>{"ground_plane", "unit_box", "cafe_table",
                                             "one_DOF_robot"}));
  const WorldFileModel& box = file.models[1];
  EXPECT_EQ(box.pose.position.x, 2.5);
  EXPECT_EQ(box.pose.position.y, -1.5);
  EXPECT_NEAR(2 * std::atan2(box.pose.orientation.z, box.pose.orientation.w), 1.2, 1e-12);
  ASSERT_TRUE(file.state.has_value());
  EXPECT_EQ(file.state->sim_time_ns, 91335000000);
  EXPECT_EQ(file.state->iterations, 91335u);
  EXPECT_TRUE(file.state->unknown_models.empty());
  EXPECT_TRUE(file.state->not_applied.empty());
  std::vector<std::string> ignored;
  for (const WorldFileIgnored& element : file.ignored) ignored.push_back(element.element);
  EXPECT_EQ(ignored, (std::vector<std::string>{"light", "magnetic_field", "atmosphere", "scene",
                                               "audio", "wind", "spherical_coordinates", "gui"}));

  for (const std::string& engine : World::engineNames()) {
    World world(engine, file.physics.at(engine));
    world.setModelPath(kModelPath);
    for (const WorldFileModel& model : file.models)
      ASSERT_TRUE(world.spawn(model.name, model.sdf, ModelFormat::Sdf, model.pose).ok())
          << engine << " " << model.name;
    ASSERT_TRUE(world.setClock(file.state->sim_time_ns, file.state->iterations).ok());
    for (int i = 0; i < 500; ++i) ASSERT_TRUE(world.step().ok()) << engine;
    EXPECT_EQ(world.timeNs(), 91835000000) << engine;
    EXPECT_EQ(world.stepCount(), 91835u) << engine;
    Pose pose;
    Twist twist;
    ASSERT_TRUE(world.modelState("unit_box", "", &pose, &twist).ok());
    EXPECT_NEAR(pose.position.x, 2.5, 1e-3) << engine;
    EXPECT_NEAR(pose.position.z, 0.5, 2e-3) << engine;
    ASSERT_TRUE(world.linkState("one_DOF_robot::link2", "", &pose, &twist).ok());
    EXPECT_NEAR(pose.position.x, -1, 1e-6) << engine;
    EXPECT_NEAR(pose.position.z, 1, 1e-6) << engine;
  }
}

// What Gazebo's reader takes and libsdformat's DOM refuses or renames, in the shapes of
// gazebo_ros_pkgs' test worlds: a <script> that names a material in its text (Gazebo shows no
// named material then), a camera's 16-bit format, an attribute the schema does not define,
// <visualize>True</visualize>, a negative friction coefficient (Gazebo's unbounded friction) and
// a joint named as a link (libsdformat 12 renames it, Gazebo keeps the name).
TEST_F(WorldFileTest, WhatGazebosReaderTakesLoadsAndSpawns) {
  WorldFile file;
  const WorldFileStatus status = read(
      "<include><uri>model://ground_plane</uri></include>"
      "<gui fullscreen='0'><camera name='user_camera'><pose>4 -4 3 0 0.27 2.35</pose>"
      "<view_controller>orbit</view_controller></camera></gui>"
      "<model name='ball'><pose>2 0 1 0 0 0</pose><link name='link'>"
      "<inertial><mass>10</mass><inertia><ixx>1</ixx><iyy>1</iyy><izz>1</izz></inertia>"
      "</inertial><visual name='v'><geometry><sphere><radius>0.5</radius></sphere></geometry>"
      "<material><ambient>0.03 0.5 0.5 1</ambient><script>Gazebo/Green</script></material>"
      "</visual><collision name='c'><geometry><sphere><radius>0.5</radius></sphere></geometry>"
      "<surface><friction><ode><mu>-1</mu><mu2>-1</mu2></ode></friction></surface>"
      "</collision></link></model>"
      "<model name='camera_model'><static>true</static><pose>0 0 0.5 0 0 0</pose>"
      "<link name='camera_link'><sensor type='camera' name='camera1'><update_rate>0.5"
      "</update_rate><visualize>True</visualize><camera name='head'><horizontal_fov>1.39"
      "</horizontal_fov><image><width>64</width><height>48</height><format>R16G16B16</format>"
      "</image><clip near='0.01' far='100'><near>0.02</near><far>300</far></clip></camera>"
      "</sensor></link></model>"
      "<model name='lift'><link name='door'><inertial><mass>1</mass></inertial>"
      "<collision name='c'><geometry><box><size>0.1 1 2</size></box></geometry></collision>"
      "</link><joint name='door' type='prismatic'><parent>world</parent><child>door</child>"
      "<axis><xyz>0 1 0</xyz><limit><lower>0</lower><upper>1</upper></limit></axis></joint>"
      "</model>",
      &file);
  ASSERT_TRUE(status.ok()) << status.subject;
  ASSERT_EQ(file.models.size(), 4u);
  for (const std::string& engine : World::engineNames()) {
    World world(engine);
    world.setModelPath(kModelPath);
    for (const WorldFileModel& model : file.models)
      ASSERT_TRUE(world.spawn(model.name, model.sdf, ModelFormat::Sdf, model.pose).ok())
          << engine << " " << model.name << "\n" << model.sdf;
    JointInfo door;
    EXPECT_TRUE(world.jointInfo("door", &door).ok()) << engine;
    EXPECT_EQ(door.model, "lift");
    for (const VisualShape& visual : world.visualShapes())
      if (visual.model == "ball") {
        EXPECT_EQ(visual.material.script, "") << engine;
        ASSERT_TRUE(visual.material.ambient.has_value());
        EXPECT_FLOAT_EQ(visual.material.ambient->g, 0.5f);
      }
    for (int i = 0; i < 1000; ++i) world.step();
    Pose pose;
    Twist twist;
    ASSERT_TRUE(world.modelState("ball", "", &pose, &twist).ok());
    EXPECT_NEAR(pose.position.z, 0.5, 2e-3) << engine;
  }
}

// A plane collision is the plane z = 0 of its frame, unbounded whatever its <size>, on a static
// model (a deck 0.3 m up, tilted about x) and on a moving link, where it stays where the link was
// placed, as Gazebo's does; a box dropped on the deck comes to rest on it.
TEST_F(WorldFileTest, PlaneCollisionsHoldWhatFallsOnThem) {
  const std::string deck =
      "<sdf version='1.6'><model name='deck'><static>1</static>"
      "<link name='link'><collision name='c'><geometry><plane><normal>0 0 1</normal>"
      "<size>1 1</size></plane></geometry></collision></link></model></sdf>";
  const std::string box =
      "<sdf version='1.6'><model name='box'><link name='link'><inertial><mass>1</mass><inertia>"
      "<ixx>0.0017</ixx><iyy>0.0017</iyy><izz>0.0017</izz></inertia></inertial>"
      "<collision name='c'><geometry><box><size>0.1 0.1 0.1</size></box></geometry>"
      "</collision></link></model></sdf>";
  for (const std::string& engine : World::engineNames()) {
    World world(engine);
    const Pose deck_pose{{0, 0, 0.3}, {std::cos(0.1), std::sin(0.1), 0, 0}};  // 0.2 rad about x
    ASSERT_TRUE(world.spawn("deck", deck, ModelFormat::Sdf, deck_pose).ok()) << engine;
    Pose above;
    above.position = {5, 0.3, 0.6};  // 5 m out: the plane's <size> of 1 m does not bound it
    ASSERT_TRUE(world.spawn("box", box, ModelFormat::Sdf, above).ok()) << engine;
    for (int i = 0; i < 1500; ++i) world.step();
    Pose pose;
    Twist twist;
    ASSERT_TRUE(world.modelState("box", "", &pose, &twist).ok());
    // The deck's surface at y: z = 0.3 + y tan(0.2); the box rests on it, the 0.05 m half
    // side along the deck's normal.
    const double surface = 0.3 + pose.position.y * std::tan(0.2);
    EXPECT_NEAR(pose.position.z, surface + 0.05 / std::cos(0.2), 5e-3) << engine;
    EXPECT_NEAR(pose.position.x, 5, 0.05) << engine;
  }
}

void expectSamePose(const Pose& a, const Pose& b, const std::string& what) {
  EXPECT_EQ(a.position.x, b.position.x) << what;
  EXPECT_EQ(a.position.y, b.position.y) << what;
  EXPECT_EQ(a.position.z, b.position.z) << what;
  EXPECT_EQ(a.orientation.w, b.orientation.w) << what;
  EXPECT_EQ(a.orientation.x, b.orientation.x) << what;
  EXPECT_EQ(a.orientation.y, b.orientation.y) << what;
  EXPECT_EQ(a.orientation.z, b.orientation.z) << what;
}

// Two worlds of the same models: the same models, links, joints and shapes where they are.
void expectSameWorlds(const World& a, const World& b, const std::string& what) {
  ASSERT_EQ(a.modelNames(), b.modelNames()) << what;
  for (const std::string& name : a.modelNames()) {
    ModelInfo info_a, info_b;
    ASSERT_TRUE(a.modelProperties(name, &info_a).ok());
    ASSERT_TRUE(b.modelProperties(name, &info_b).ok());
    EXPECT_EQ(info_a.links, info_b.links) << what << " " << name;
    EXPECT_EQ(info_a.geoms, info_b.geoms) << what << " " << name;
    EXPECT_EQ(info_a.joints, info_b.joints) << what << " " << name;
    EXPECT_EQ(info_a.canonical_link, info_b.canonical_link) << what << " " << name;
    EXPECT_EQ(info_a.is_static, info_b.is_static) << what << " " << name;
    for (const std::string& link : info_a.links) {
      Pose pose_a, pose_b;
      Twist twist;
      ASSERT_TRUE(a.linkState(link, "", &pose_a, &twist).ok()) << link;
      ASSERT_TRUE(b.linkState(link, "", &pose_b, &twist).ok()) << link;
      expectSamePose(pose_a, pose_b, what + " " + link);
    }
  }
  const std::vector<CollisionShape> collisions_a = a.collisionShapes();
  const std::vector<CollisionShape> collisions_b = b.collisionShapes();
  ASSERT_EQ(collisions_a.size(), collisions_b.size()) << what;
  for (size_t i = 0; i < collisions_a.size(); ++i) {
    const std::string shape = what + " collision of " + collisions_a[i].link;
    EXPECT_EQ(collisions_a[i].link, collisions_b[i].link) << shape;
    EXPECT_EQ(collisions_a[i].shape, collisions_b[i].shape) << shape;
    EXPECT_EQ(collisions_a[i].size.x, collisions_b[i].size.x) << shape;
    EXPECT_EQ(collisions_a[i].size.z, collisions_b[i].size.z) << shape;
    EXPECT_EQ(collisions_a[i].mesh_file, collisions_b[i].mesh_file) << shape;
    expectSamePose(collisions_a[i].pose, collisions_b[i].pose, shape);
  }
  const std::vector<VisualShape> visuals_a = a.visualShapes();
  const std::vector<VisualShape> visuals_b = b.visualShapes();
  ASSERT_EQ(visuals_a.size(), visuals_b.size()) << what;
  for (size_t i = 0; i < visuals_a.size(); ++i) {
    const std::string shape = what + " visual " + visuals_a[i].name;
    EXPECT_EQ(visuals_a[i].name, visuals_b[i].name) << shape;
    EXPECT_EQ(visuals_a[i].shape, visuals_b[i].shape) << shape;
    EXPECT_EQ(visuals_a[i].mesh_uri, visuals_b[i].mesh_uri) << shape;
    expectSamePose(visuals_a[i].pose, visuals_b[i].pose, shape);
  }
}

// A world's models are made from the file's own reading (World::prepare(WorldFileModel)), not
// read again: they are the models their documents make, refused alike, in every shape of world
// the tests load (gazebo_ros_pkgs' test worlds, a world saved by Gazebo), in this package's
// worlds (willowgarage.world's model is not among its models) and in models a limit or a check
// refuses, and they step alike.
TEST_F(WorldFileTest, AWorldsModelsAreTheModelsTheirDocumentsMake) {
  std::vector<std::string> files;
  for (const char* folder : {ONEDOF_SOURCE_DIR "/tests/worlds",
                             ONEDOF_SOURCE_DIR "/src/onedof_sim/worlds"})
    for (const auto& entry : std::filesystem::directory_iterator(folder))
      if (entry.path().filename() != "willowgarage.world") files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  std::string many_links;
  for (int i = 0; i <= 1000; ++i) many_links += "<link name='l" + std::to_string(i) + "'/>";
  files.push_back(write(
      "<sdf version='1.6'><world name='w'>"
      "<model name='heavy'><link name='l'><inertial><mass>1e9</mass></inertial></link></model>"
      "<model name='many'>" + many_links + "</model>"
      "<model name='huge'><link name='l'><collision name='c'><geometry><box>"
      "<size>2000 1 1</size></box></geometry></collision></link></model>"
      "<model name='meshless'><pose>1 2 3 0 0.5 0</pose><link name='l'><collision name='c'>"
      "<geometry><mesh><uri>model://nowhere/x.stl</uri></mesh></geometry></collision>"
      "</link></model></world></sdf>"));
  size_t refused = 0, left_out = 0;
  for (const std::string& path : files) {
    WorldFile file;
    const WorldFileStatus status = readWorldFile(path, kModelPath, {}, &file);
    ASSERT_TRUE(status.ok()) << path << ": " << status.subject;
    World from_file(World::engineNames().front(), file.physics.begin()->second);
    World from_document(World::engineNames().front(), file.physics.begin()->second);
    from_file.setModelPath(kModelPath);
    from_document.setModelPath(kModelPath);
    for (const WorldFileModel& model : file.models) {
      const std::string what = path + " " + model.name;
      PreparedModel read_once = World::prepare(model);
      PreparedModel read_again = World::prepare(model.sdf, ModelFormat::Sdf, kModelPath);
      EXPECT_EQ(read_once.status().code, read_again.status().code) << what;
      EXPECT_EQ(read_once.status().subject, read_again.status().subject) << what;
      EXPECT_EQ(read_once.leftOut(), read_again.leftOut()) << what;
      EXPECT_EQ(read_once.warnings().size(), read_again.warnings().size()) << what;
      refused += !read_once.status().ok();
      left_out += read_once.leftOut().size();
      if (!read_once.status().ok()) continue;
      ASSERT_TRUE(from_file.spawn(model.name, std::move(read_once), model.pose).ok()) << what;
      ASSERT_TRUE(from_document.spawn(model.name, std::move(read_again), model.pose).ok()) << what;
    }
    expectSameWorlds(from_file, from_document, path);
    for (int i = 0; i < 200; ++i) {
      from_file.step();
      from_document.step();
    }
    expectSameWorlds(from_file, from_document, path + " after 200 steps");
  }
  EXPECT_EQ(refused, 3u);  // heavy, many, huge
  EXPECT_GE(left_out, 1u);  // meshless
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

// A folder, a FIFO and a device are refused as what they are, never opened: reading a FIFO would
// wait for a writer, /dev/zero would never end.
TEST_F(WorldFileTest, APathThatIsNoFileIsRefusedAsWhatItIs) {
  WorldFile world;
  WorldFileStatus status = readWorldFile(folder_.string(), kModelPath, {}, &world);
  EXPECT_EQ(status.code, WorldFileCode::NotAFile);
  EXPECT_EQ(status.subject, "directory");
  const std::string fifo = (folder_ / "pipe.world").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  status = readWorldFile(fifo, kModelPath, {}, &world);
  EXPECT_EQ(status.code, WorldFileCode::NotAFile);
  EXPECT_EQ(status.subject, "FIFO");
  status = readWorldFile("/dev/zero", kModelPath, {}, &world);
  EXPECT_EQ(status.code, WorldFileCode::NotAFile);
  EXPECT_EQ(status.subject, "character device");
}

// Model folders of the model path: NAME/model.config naming model.sdf, a model whose content is
// `content` (links, includes).
class IncludeGraphTest : public WorldFileTest {
 protected:
  void model(const std::string& name, const std::string& content) {
    const std::filesystem::path dir = folder_ / "models" / name;
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "model.config")
        << "<?xml version=\"1.0\"?><model><name>" << name
        << "</name><sdf version=\"1.6\">model.sdf</sdf></model>";
    std::ofstream(dir / "model.sdf") << "<?xml version=\"1.0\"?><sdf version=\"1.6\"><model name=\""
                                     << name << "\">" << content << "</model></sdf>";
  }
  static std::string include(const std::string& name, const std::string& as) {
    return "<include><uri>model://" + name + "</uri><name>" + as + "</name></include>";
  }
  WorldFileStatus readWithModels(const std::string& world_content, WorldFile* out) {
    return readWorldFile(write("<sdf version=\"1.6\"><world name=\"w\">" + world_content +
                               "</world></sdf>"),
                         {(folder_ / "models").string()}, {}, out);
  }
  std::string file(const std::string& name) {
    return (folder_ / "models" / name / "model.sdf").string();
  }
};

TEST_F(IncludeGraphTest, IncludesThatIncludeThemselvesAreRefusedNamingTheCycle) {
  model("self", "<link name=\"l\"/>" + include("self", "again"));
  WorldFile world;
  WorldFileStatus status = readWithModels(include("self", "s"), &world);
  EXPECT_EQ(status.code, WorldFileCode::IncludeCycle);
  EXPECT_EQ(status.subject, file("self") + " -> " + file("self"));
  model("a", "<link name=\"l\"/>" + include("b", "b"));
  model("b", "<link name=\"l\"/>" + include("a", "a"));
  status = readWithModels(include("a", "a"), &world);
  EXPECT_EQ(status.code, WorldFileCode::IncludeCycle);
  EXPECT_EQ(status.subject, file("a") + " -> " + file("b") + " -> " + file("a"));
}

// model:// is confined to the model path: a model beside it, reached by climbing out, is refused
// in the words of a missing one.
TEST_F(IncludeGraphTest, AnIncludeThatClimbsOutOfTheModelPathIsNotFound) {
  model("../elsewhere", "<link name=\"l\"/>");
  WorldFile world;
  const WorldFileStatus status = readWithModels(include("../elsewhere", "e"), &world);
  EXPECT_EQ(status.code, WorldFileCode::IncludeNotFound);
  EXPECT_EQ(status.subject, "model://../elsewhere");
  const PreparedModel prepared = World::prepare(
      "<sdf version=\"1.6\"><model name=\"m\"><link name=\"l\"/>" +
          include("inside/../../elsewhere", "e") + "</model></sdf>",
      ModelFormat::Sdf, {(folder_ / "models").string()});
  EXPECT_EQ(prepared.status().code, StatusCode::ModelRejected);
  EXPECT_EQ(prepared.status().subject.find("model://inside/../../elsewhere is not in the model path"),
            0u)
      << prepared.status();
}

// A spawned SDF document's includes are checked as a world file's.
TEST_F(IncludeGraphTest, ASpawnedModelThatIncludesItselfIsRefused) {
  model("self", "<link name=\"l\"/>" + include("self", "again"));
  const PreparedModel prepared = World::prepare(
      "<sdf version=\"1.6\"><model name=\"m\"><link name=\"l\"/>" + include("self", "s") +
          "</model></sdf>",
      ModelFormat::Sdf, {(folder_ / "models").string()});
  EXPECT_EQ(prepared.status().code, StatusCode::ModelRejected);
  EXPECT_EQ(prepared.status().subject,
            "invalid SDF: its <include>s include themselves: " + file("self") + " -> " +
                file("self"));
}

// level0 includes level1 twice, ..., level15 level16 twice: with the world's include of level0,
// 2^17 - 1 models from 17 small files,
// refused from the counts; 2^9 - 2 are within the limit and load.
TEST_F(IncludeGraphTest, AnIncludeTreeIsCountedBeforeItIsRead) {
  const int levels = 17;
  for (int level = 0; level < levels; ++level) {
    const std::string next = "level" + std::to_string(level + 1);
    model("level" + std::to_string(level),
          "<link name=\"l\"/>" + (level + 1 < levels ? include(next, "x") + include(next, "y")
                                                     : std::string()));
  }
  WorldFile world;
  WorldFileStatus status = readWithModels(include("level0", "tree"), &world);
  EXPECT_EQ(status.code, WorldFileCode::TooManyIncludedModels);
  EXPECT_EQ(status.subject, std::to_string((1 << 17) - 1));
  EXPECT_EQ(status.max, 1000);
  // A chain of 1001 files, each including the next: counting stops at the 1001st file.
  for (int link = 0; link <= 1000; ++link)
    model("chain" + std::to_string(link),
          "<link name=\"l\"/>" +
              (link < 1000 ? include("chain" + std::to_string(link + 1), "next") : std::string()));
  status = readWithModels(include("chain0", "chain"), &world);
  EXPECT_EQ(status.code, WorldFileCode::TooManyIncludedModels);
  EXPECT_EQ(status.subject, "at least 1001");
  status = readWithModels(include("level8", "tree"), &world);
  EXPECT_TRUE(status.ok()) << status.subject;
  ASSERT_EQ(world.models.size(), 1u);
}

}  // namespace
}  // namespace onedof_sim
