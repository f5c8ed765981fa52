#include "ray_sensor.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <utility>

#include <onedof_sim/pose_math.h>
#include <ros/console.h>
#include <tinyxml2.h>

#include "sensor_xml.h"

namespace onedof_sim::plugins {
namespace {

// More rays than any laser has (a 3D lidar: 128 x 2048), for a scan that stays a fraction of a
// step's time.
constexpr long kMaxRays = 262144;
// The rays of one query of a measurement's part (RayScanner::castPart), which looks at the
// clock between queries: a small part of a millisecond on either engine.
constexpr size_t kRaysPerQuery = 256;

bool readCount(const tinyxml2::XMLElement* parent, const std::string& where, int* value,
               std::string* error) {
  double number = *value;
  if (!readSensorNumber(parent, "samples", where, &number, error)) return false;
  if (number < 1 || number != std::floor(number) || number > kMaxRays) {
    *error = "<" + where + "><samples> is " + std::to_string(number) + ", not a count of rays";
    return false;
  }
  *value = static_cast<int>(number);
  return true;
}

// Place `index` of `count` evenly from min to max (one: at min).
double spread(int index, int count, double min, double max) {
  return count == 1 ? min : index * (max - min) / (count - 1) + min;
}

std::string describe(const Status& status) {
  std::ostringstream text;
  text << status;
  return text.str();
}

}  // namespace

int RayConfig::rangeCount() const { return static_cast<int>(samples * resolution); }
int RayConfig::verticalRangeCount() const {
  return static_cast<int>(vertical_samples * vertical_resolution);
}
double RayConfig::angleIncrement() const { return (max_angle - min_angle) / (rangeCount() - 1); }

double RayConfig::rangeYaw(int column) const {
  return samples == 1 ? 0 : spread(column, rangeCount(), min_angle, max_angle);
}

double RayConfig::rangePitch(int row) const {
  return vertical_samples == 1
             ? 0
             : spread(row, verticalRangeCount(), vertical_min_angle, vertical_max_angle);
}

bool readRayConfig(const std::string& sensor_xml, RayConfig* config, std::string* error) {
  tinyxml2::XMLDocument doc;
  const tinyxml2::XMLElement* ray = requiredSensorChild(sensor_xml, "ray", &doc, error);
  if (!ray) return false;
  RayConfig c;
  const auto* horizontal = sensorPath(ray, {"scan", "horizontal"});
  const auto* vertical = sensorPath(ray, {"scan", "vertical"});
  const auto* range = sensorPath(ray, {"range"});
  if (!readCount(horizontal, "horizontal", &c.samples, error) ||
      !readSensorNumber(horizontal, "resolution", "horizontal", &c.resolution, error) ||
      !readSensorNumber(horizontal, "min_angle", "horizontal", &c.min_angle, error) ||
      !readSensorNumber(horizontal, "max_angle", "horizontal", &c.max_angle, error) ||
      !readCount(vertical, "vertical", &c.vertical_samples, error) ||
      !readSensorNumber(vertical, "resolution", "vertical", &c.vertical_resolution, error) ||
      !readSensorNumber(vertical, "min_angle", "vertical", &c.vertical_min_angle, error) ||
      !readSensorNumber(vertical, "max_angle", "vertical", &c.vertical_max_angle, error) ||
      !readSensorNumber(range, "min", "range", &c.range_min, error) ||
      !readSensorNumber(range, "max", "range", &c.range_max, error) ||
      !readSensorNumber(range, "resolution", "range", &c.range_resolution, error))
    return false;
  if (!(c.resolution > 0) || !(c.vertical_resolution > 0) || c.rangeCount() < 1 ||
      c.verticalRangeCount() < 1 ||
      static_cast<long>(c.rangeCount()) * c.verticalRangeCount() > kMaxRays) {
    *error = "<scan> <resolution> makes " + std::to_string(c.rangeCount()) + " x " +
             std::to_string(c.verticalRangeCount()) + " ranges, not 1 to " +
             std::to_string(kMaxRays);
    return false;
  }
  if (c.range_min < 0 || !(c.range_max > c.range_min)) {
    *error = "<range> is min " + std::to_string(c.range_min) + " max " +
             std::to_string(c.range_max) + ": it needs 0 <= min < max";
    return false;
  }
  if (!readNoise(ray->FirstChildElement("noise"), "<ray><noise>", &c.noise, error)) return false;
  *config = c;
  return true;
}

RayScanner::RayScanner(const RayConfig& config, std::string link, const Pose& pose,
                       uint64_t seed)
    : config_(config), link_(std::move(link)), pose_(pose), random_(seed) {
  // Gazebo's MultiRayShape: a lone ray (or row) points along x (has no pitch).
  const RayConfig& c = config_;
  for (int j = 0; j < c.vertical_samples; ++j) {
    const double pitch = c.vertical_samples == 1 ? 0
                                                 : spread(j, c.vertical_samples,
                                                          c.vertical_min_angle, c.vertical_max_angle);
    for (int i = 0; i < c.samples; ++i) {
      const double yaw = c.samples == 1 ? 0 : spread(i, c.samples, c.min_angle, c.max_angle);
      directions_.push_back({std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                             std::sin(pitch)});
    }
  }
  rays_.resize(directions_.size());
  noise_ = NoiseModel(c.noise, random_);
}

bool RayScanner::start(const World& world, std::string* why) {
  const RayConfig& c = config_;
  Pose link_pose;
  Twist unused;
  const Status status = world.linkState(link_, "", &link_pose, &unused);
  if (!status.ok()) {
    *why = "its link's pose: " + describe(status);
    return false;
  }
  const Pose sensor = compose(link_pose, pose_);
  const double span = c.range_max - c.range_min;
  for (size_t k = 0; k < directions_.size(); ++k) {
    const Vec3 d = rotate(sensor.orientation, directions_[k]);
    rays_[k] = {{sensor.position.x + d.x * c.range_min, sensor.position.y + d.y * c.range_min,
                 sensor.position.z + d.z * c.range_min},
                d, span};
  }
  casts_.clear();
  return true;
}

RayScanner::Cast RayScanner::castPart(World& world, SensorWork::Clock::time_point until,
                                      std::string* why) {
  do {
    const size_t first = casts_.size();
    const size_t count = std::min(kRaysPerQuery, rays_.size() - first);
    part_.assign(rays_.begin() + first, rays_.begin() + first + count);
    const Status status = world.castRays(part_, &part_casts_);
    if (!status.ok()) {
      *why = "the ray query: " + describe(status);
      casts_.clear();
      return Cast::Failed;
    }
    casts_.insert(casts_.end(), part_casts_.begin(), part_casts_.end());
  } while (casts_.size() < rays_.size() && SensorWork::Clock::now() < until);
  if (casts_.size() < rays_.size()) return Cast::More;
  hits_.swap(casts_);
  casts_.clear();
  return Cast::Done;
}

double RayScanner::rayRange(int row, int column) const {
  const RayConfig& c = config_;
  if (hits_.empty()) return c.range_max;  // nothing measured yet
  const double hit = hits_[static_cast<size_t>(row) * c.samples + column];
  return c.range_min + (std::isfinite(hit) ? hit : c.range_max - c.range_min);
}

double RayScanner::range(int row, int column) const {
  const RayConfig& c = config_;
  const int columns = c.rangeCount(), rows = c.verticalRangeCount();
  if (columns == c.samples && rows == c.vertical_samples) return rayRange(row, column);
  double vb = rows == 1 ? 0 : static_cast<double>(row * (c.vertical_samples - 1)) / (rows - 1);
  const int vja = static_cast<int>(std::floor(vb));
  const int vjb = std::min(vja + 1, c.vertical_samples - 1);
  vb -= std::floor(vb);
  double hb = columns == 1 ? 0 : static_cast<double>(column * (c.samples - 1)) / (columns - 1);
  const int hja = static_cast<int>(std::floor(hb));
  const int hjb = std::min(hja + 1, c.samples - 1);
  hb -= std::floor(hb);
  return (1 - vb) * ((1 - hb) * rayRange(vja, hja) + hb * rayRange(vja, hjb)) +
         vb * ((1 - hb) * rayRange(vjb, hja) + hb * rayRange(vjb, hjb));
}

void RayScanner::scan(std::vector<float>* ranges) {
  const RayConfig& c = config_;
  const int columns = c.rangeCount(), rows = c.verticalRangeCount();
  ranges->resize(static_cast<size_t>(columns) * rows);
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i) {
      double value = range(j, i);
      // REP 117, as Gazebo masks them.
      if (value >= c.range_max) {
        value = std::numeric_limits<double>::infinity();
      } else if (value <= c.range_min) {
        value = -std::numeric_limits<double>::infinity();
      } else if (noise_.on()) {
        value = std::clamp(noise_.apply(value, random_), c.range_min, c.range_max);
      }
      (*ranges)[static_cast<size_t>(j) * columns + i] = static_cast<float>(value);
    }
}

namespace {

class MeasurementWork : public SensorWork {
 public:
  MeasurementWork(RayScanner* scanner, std::string label, const char* what, bool* failed,
                  std::function<void()> measured)
      : scanner_(scanner), label_(std::move(label)), what_(what), failed_(failed),
        measured_(std::move(measured)) {}

  bool withWorld(World& world, Clock::time_point until) override {
    std::string why;
    if (!started_) {
      if (!scanner_->start(world, &why)) return fail(why);
      started_ = true;
    }
    switch (scanner_->castPart(world, until, &why)) {
      case RayScanner::Cast::More: return false;
      case RayScanner::Cast::Done: measured_(); return true;
      case RayScanner::Cast::Failed: return fail(why);
    }
    return true;
  }

 private:
  bool fail(const std::string& why) {
    if (!*failed_) ROS_ERROR_STREAM(label_ << " measured no " << what_ << ": " << why);
    *failed_ = true;
    return true;
  }

  RayScanner* scanner_;
  std::string label_;
  const char* what_;
  bool* failed_;
  std::function<void()> measured_;
  bool started_ = false;
};

}  // namespace

std::shared_ptr<SensorWork> measurementWork(RayScanner* scanner, const std::string& label,
                                            const char* what, bool* failed,
                                            std::function<void()> measured) {
  return std::make_shared<MeasurementWork>(scanner, label, what, failed, std::move(measured));
}

}  // namespace onedof_sim::plugins
