#include "sensor_noise.h"

#include <cmath>
#include <utility>

#include <onedof_sim/trim.h>

#include "sensor_xml.h"

namespace onedof_sim::plugins {

bool readNoise(const tinyxml2::XMLElement* noise, const std::string& where, NoiseParams* params,
               std::string* error) {
  *params = {};
  if (!noise) return true;
  // readSensorNumber names "<element><tag>": `where` is "<a><b>", its element "a><b".
  const std::string element = where.size() > 2 ? where.substr(1, where.size() - 2) : where;
  const char* attribute = noise->Attribute("type");
  std::string type = attribute ? attribute : "";
  if (type.empty()) {
    const tinyxml2::XMLElement* child = noise->FirstChildElement("type");
    if (child) type = trimmed(child->GetText());
  }
  if (type == "none") return true;
  if (type != "gaussian" && type != "gaussian_quantized") {
    *error = where + " has type '" + type + "': only gaussian, gaussian_quantized and none are "
             "simulated";
    return false;
  }
  NoiseParams p;
  p.on = true;
  for (const auto& [tag, value] :
       {std::pair{"mean", &p.mean}, std::pair{"stddev", &p.stddev},
        std::pair{"bias_mean", &p.bias_mean}, std::pair{"bias_stddev", &p.bias_stddev},
        std::pair{"precision", &p.precision}})
    if (!readSensorNumber(noise, tag, element, value, error)) return false;
  double unused = 0;
  for (const char* tag : {"dynamic_bias_stddev", "dynamic_bias_correlation_time"})
    if (!readSensorNumber(noise, tag, element, &unused, error)) return false;
  if (p.stddev < 0 || p.bias_stddev < 0 || p.precision < 0) {
    *error = where + " has a negative stddev, bias_stddev or precision";
    return false;
  }
  *params = p;
  return true;
}

Noise::Noise(const NoiseParams& params, std::mt19937_64& random) : params_(params) {
  if (!params_.on || (params_.bias_mean == 0 && params_.bias_stddev == 0)) return;
  bias_ = std::normal_distribution<double>(params_.bias_mean, params_.bias_stddev)(random);
  if (std::uniform_real_distribution<double>(0, 1)(random) < 0.5) bias_ = -bias_;
}

double Noise::apply(double value, std::mt19937_64& random) const {
  if (!params_.on) return value;
  const double white =
      params_.stddev > 0
          ? std::normal_distribution<double>(params_.mean, params_.stddev)(random)
          : params_.mean;
  double out = value + white + bias_;
  if (params_.precision > 0) out = std::round(out / params_.precision) * params_.precision;
  return out;
}

uint64_t seedOf(const std::string& text) {
  uint64_t hash = 14695981039346656037ull;
  for (unsigned char c : text) hash = (hash ^ c) * 1099511628211ull;
  return hash;
}

}  // namespace onedof_sim::plugins
