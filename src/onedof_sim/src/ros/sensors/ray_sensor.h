// Gazebo's ray sensor (`ray` and `gpu_ray`): its <ray> element, and its scans measured through
// World::castRays against every model's collision shapes, as Gazebo's RaySensor and
// GpuRaySensor report them.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <onedof_sim/world.h>

#include "plugins/model_plugin.h"
#include "sensor_noise.h"

namespace onedof_sim::plugins {

// <ray>: the scan's rays and their range, with SDF's defaults.
struct RayConfig {
  int samples = 640;  // <scan><horizontal>: rays
  double resolution = 1;  // ranges per ray (Gazebo interpolates between rays)
  double min_angle = 0, max_angle = 0;  // rad, about the sensor's z axis
  int vertical_samples = 1;  // <scan><vertical>
  double vertical_resolution = 1;
  double vertical_min_angle = 0, vertical_max_angle = 0;  // rad, up from the x-y plane
  double range_min = 0, range_max = 0;  // <range><min>, <max>, m
  double range_resolution = 0;  // <range><resolution>: read, not applied, as in Gazebo
  NoiseParams noise;  // <noise>: added to each range (sensor_noise.h), then held within the range

  int rangeCount() const;          // ranges per row: samples * resolution
  int verticalRangeCount() const;  // rows
  // The angle between neighbouring ranges, as Gazebo's AngleResolution gives it.
  double angleIncrement() const;
  // The direction of range `column` of a row (about the sensor's z) and of row `row` (up from
  // the x-y plane), rad: between its rays' as its value is (RayScanner::range); a lone ray or
  // row points along x, as Gazebo's.
  double rangeYaw(int column) const;
  double rangePitch(int row) const;
};

// Reads the <ray> of a <sensor> element (its XML text); false, with *error naming what is wrong,
// when it is malformed or past what a scan can be.
bool readRayConfig(const std::string& sensor_xml, RayConfig* config, std::string* error);

// Measures one ray sensor: its rays start at range_min along their directions from the sensor's
// pose on its link, as Gazebo's do, and meet every collision shape, the sensor's own link's
// included.
class RayScanner {
 public:
  // link: scoped "model::link"; pose: the sensor on it; seed: the noise's generator's.
  RayScanner(const RayConfig& config, std::string link, const Pose& pose, uint64_t seed);

  // A measurement at the world's present state, in parts (measurementWork): start takes the
  // link's pose and aims the rays, false with *why when the world cannot give the pose; castPart
  // casts the rays not yet cast until `until` has passed (a part at least), and says whether all
  // are cast, which makes them the measurement, or the query failed (*why; the last measurement
  // kept). The world must not change between the two.
  bool start(const World& world, std::string* why);
  enum class Cast { More, Done, Failed };
  Cast castPart(World& world, SensorWork::Clock::time_point until, std::string* why);
  // Of the last measurement: ray (row, column)'s range from the sensor, range_max where it met
  // nothing, as Gazebo's ray shape gives it (MultiRayShape::GetRange: no noise, no masking).
  double rayRange(int row, int column) const;
  // Of the last measurement: range (row, column) of the scan (rangeCount by verticalRangeCount),
  // Gazebo's bilinear interpolation between the four rays around it; a ray's own range at a
  // resolution of 1.
  double range(int row, int column) const;

  // The last measurement as Gazebo's ray sensor reports a scan: the ranges row after row, each
  // from min_angle to max_angle, +inf where a ray meets nothing before range_max, -inf where it
  // meets something at range_min, else the distance with the <ray><noise> added, held within the
  // range.
  void scan(std::vector<float>* ranges);

  const RayConfig& config() const { return config_; }

 private:
  RayConfig config_;
  std::string link_;
  Pose pose_;
  std::vector<Vec3> directions_;  // each ray's, in the sensor frame
  std::vector<Ray> rays_;
  std::vector<double> hits_;   // the last measurement's, per ray: castRays' distances
  std::vector<double> casts_;  // the query's answers so far, before they are the measurement
  std::vector<Ray> part_;      // the rays of one castPart's query
  std::vector<double> part_casts_;
  NoiseRandom random_;
  NoiseModel noise_;  // drawn from random_
};

// A measurement of `scanner` as sensor work: started and its rays cast part by part with the
// world locked; then `measured` is called, the world still locked (the plugin that made the work
// there). A measurement that fails is logged once, as "<label> measured no <what>: <why>"
// (*failed: it has been).
std::shared_ptr<SensorWork> measurementWork(RayScanner* scanner, const std::string& label,
                                            const char* what, bool* failed,
                                            std::function<void()> measured);

}  // namespace onedof_sim::plugins
