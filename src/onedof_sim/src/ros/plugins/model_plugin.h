// The model-plugin seam: what a Gazebo model plugin (`<plugin filename="libgazebo_ros_XXX.so">` in
// a spawned URDF's <gazebo> or an SDF <model>) is here.
//
// As in gzserver, a plugin is created when its model is spawned and lives until the model is
// deleted; the loop (SimLoop) calls it under the world lock before and after every step, as
// Gazebo's ConnectWorldUpdateBegin/End do, and on reset_world/reset_simulation. Messages are not
// published under the lock: a hook hands them out (takePublications) and the loop publishes them
// once the world is unlocked. A sensor's long work (a scan of many rays, a render) is handed out
// as SensorWork, which the loop does with the lock let go between its parts. A plugin is one file
// in this folder and one entry in registry.cpp.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <ros/ros.h>

#include <onedof_sim/world.h>

#include "preserialized.h"

namespace onedof_sim::plugins {

// Takes the lock the loop holds around the world.
using LockWorld = std::function<std::unique_lock<std::mutex>()>;
// A message to publish once the world is unlocked.
using Publication = std::function<void()>;

// What a sensor measures after a step that takes too long to hold the world's lock for at once.
// The loop does it before the next step, in two phases:
// - withWorld, the world locked, called again until it answers true, each call ending its part
//   once `until` has passed. Between calls the loop lets go of the lock for the requests that
//   only read the world, and holds back those that change it until every work's withWorld is
//   done: each part sees the world as the step left it, as the plugin that made the work does,
//   so a measurement is what it would be in one piece (a scan's rays cast part by part).
// - withoutWorld, unlocked, while requests of any kind are served: what needs no world (a render
//   of the scene withWorld or the hook took), and the messages to publish. A render is done on
//   the sensor thread (sensors/sensor_thread.h), at a lower priority than the threads that answer
//   requests, the loop waiting for it. The plugin may be gone by then (its model deleted): what
//   this phase uses, the work holds.
class SensorWork {
 public:
  using Clock = std::chrono::steady_clock;
  virtual ~SensorWork() = default;
  virtual bool withWorld(World& /*world*/, Clock::time_point /*until*/) { return true; }
  virtual std::vector<Publication> withoutWorld() { return {}; }
};

// The messages a plugin makes under the world lock, kept until the loop takes them
// (takePublications) to publish once it is unlocked, and its sensor work, kept until the loop
// takes it (takeSensorWork). Each is serialized as it is published, before roscpp takes its
// topic lock (preserialized.h): an image's megabytes never hold up the node's network thread.
class PublicationQueue {
 public:
  template <class Message>
  void add(const ros::Publisher& publisher, const Message& message) {
    pending_.push_back([publisher, message] { publishPreSerialized(publisher, message); });
  }
  // A message held by a shared pointer, not copied (images, point clouds).
  template <class Message>
  void add(const ros::Publisher& publisher, const boost::shared_ptr<Message>& message) {
    pending_.push_back([publisher, message] { publishPreSerialized(publisher, *message); });
  }
  std::vector<Publication> take() {
    std::vector<Publication> out;
    out.swap(pending_);
    return out;
  }
  void addWork(std::shared_ptr<SensorWork> work) { work_.push_back(std::move(work)); }
  std::vector<std::shared_ptr<SensorWork>> takeWork() {
    std::vector<std::shared_ptr<SensorWork>> out;
    out.swap(work_);
    return out;
  }

 private:
  std::vector<Publication> pending_;
  std::vector<std::shared_ptr<SensorWork>> work_;
};

// Where a hook is called: the world's sim time and step count at that moment (before a step:
// those the step starts from; after it: those it reached).
struct StepTime {
  int64_t time_ns = 0;
  uint64_t step = 0;
};

// What a plugin is created with.
struct ModelPluginContext {
  std::string model;          // the spawned model's name
  std::string name;           // <plugin name="...">
  std::string filename;       // <plugin filename="...">, the registry's key
  std::string plugin_xml;     // the <plugin> element, as XML text
  std::string model_xml;      // the whole URDF or SDF the model was spawned from
  ModelFormat format = ModelFormat::Urdf;
  std::string robot_namespace;  // <robotNamespace>, empty if the plugin has none
  ros::NodeHandle node;         // in robot_namespace ("/" when empty)
  const World* world = nullptr;  // read it only under lock_world()
  LockWorld lock_world;
};

class ModelPlugin {
 public:
  // Destroyed with the world unlocked: its services and subscribers wait for their callbacks in
  // flight, which may be waiting for the world.
  virtual ~ModelPlugin() = default;

  // World locked, around every step of the world.
  virtual void beforeStep(World& /*world*/, const StepTime& /*at*/) {}
  virtual void afterStep(World& /*world*/, const StepTime& /*at*/) {}
  // World locked: reset_world or reset_simulation.
  virtual void reset(World& /*world*/) {}
  // World locked: the model is deleted; the plugin is destroyed right after, unlocked.
  virtual void stop(World& /*world*/) {}
  // World locked, after the hooks of a step: the sensor work they left (SensorWork).
  virtual std::vector<std::shared_ptr<SensorWork>> takeSensorWork() { return {}; }
  // World locked, after the plugin's hooks of a step, and again after the withWorld phase of the
  // step's sensor work if there was any: the messages to publish once it is unlocked.
  virtual std::vector<Publication> takePublications() { return {}; }
};

// Creates a plugin, called unlocked (it may advertise and subscribe). Null and *error (why it
// was not started) when its <plugin> or its model does not suit it.
using ModelPluginFactory =
    std::function<std::unique_ptr<ModelPlugin>(const ModelPluginContext&, std::string* error)>;

// A registry entry: the plugin's Gazebo filename and its factory.
struct ModelPluginType {
  std::string filename;
  ModelPluginFactory create;
};

}  // namespace onedof_sim::plugins
