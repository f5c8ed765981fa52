#include "sensor_noise.h"

#include <cmath>
#include <utility>

#include <onedof_sim/trim.h>

#include "sensor_xml.h"

namespace onedof_sim::plugins {

uint64_t seedOf(const std::string& text) {
  uint64_t hash = 14695981039346656037ull;
  for (unsigned char c : text) hash = (hash ^ c) * 1099511628211ull;
  return hash;
}

NoiseParams whiteNoise(double stddev) {
  NoiseParams params;
  params.on = stddev > 0;
  params.stddev = stddev;
  return params;
}

bool readNoise(const tinyxml2::XMLElement* noise, const std::string& where, NoiseParams* params,
               std::string* error) {
  *params = {};
  if (!noise) return true;
  // readSensorNumber names "<element><tag>": `where` is "<a><b>", its element "a><b".
  const std::string element = where.size() > 2 ? where.substr(1, where.size() - 2) : where;
  const char* attribute = noise->Attribute("type");
  const tinyxml2::XMLElement* type_element = noise->FirstChildElement("type");
  if (!attribute && !type_element) {
    *error = where + " has no type (gaussian, gaussian_quantized or none)";
    return false;
  }
  const std::string type = trimmed(attribute ? attribute : type_element->GetText());
  if (type == "none") return true;
  if (type != "gaussian" && type != "gaussian_quantized") {
    *error = where + " has type '" + type + "': only gaussian, gaussian_quantized and none are "
             "simulated (custom needs a plugin's own noise callback, which none here sets)";
    return false;
  }
  NoiseParams p;
  p.on = true;
  for (const auto& [tag, value] :
       {std::pair{"mean", &p.mean}, std::pair{"stddev", &p.stddev},
        std::pair{"bias_mean", &p.bias_mean}, std::pair{"bias_stddev", &p.bias_stddev},
        std::pair{"dynamic_bias_stddev", &p.dynamic_bias_stddev},
        std::pair{"dynamic_bias_correlation_time", &p.dynamic_bias_correlation_time},
        std::pair{"precision", &p.precision}})
    if (!readSensorNumber(noise, tag, element, value, error)) return false;
  if (p.stddev < 0 || p.bias_stddev < 0 || p.dynamic_bias_stddev < 0 ||
      p.dynamic_bias_correlation_time < 0 || p.precision < 0) {
    *error = where + " has a negative stddev, bias_stddev, dynamic_bias_stddev, "
             "dynamic_bias_correlation_time or precision";
    return false;
  }
  *params = p;
  return true;
}

NoiseModel::NoiseModel(const NoiseParams& params, NoiseRandom& random)
    : params_(params),
      white_(params.mean, params.stddev > 0 ? params.stddev : 1.0),  // drawn only when > 0
      drift_(0.0, 1.0) {
  if (!params_.on || (params_.bias_mean == 0 && params_.bias_stddev == 0)) return;
  bias_ = std::normal_distribution<double>(params_.bias_mean, params_.bias_stddev)(random);
  if (std::uniform_real_distribution<double>(0, 1)(random) < 0.5) bias_ = -bias_;
}

double NoiseModel::white(NoiseRandom& random) {
  return params_.stddev > 0 ? white_(random) : params_.mean;
}

double NoiseModel::apply(double value, NoiseRandom& random, double elapsed_s) {
  if (!params_.on) return value;
  const double white_noise = white(random);
  if (elapsed_s > 0 && params_.drifts()) {
    // The bias over elapsed_s as a first-order Gauss-Markov process of correlation time tau
    // driven by dynamic_bias_stddev: it decays by exp(-dt / tau) and takes a step of
    // N(0, sigma^2 tau / 2 (1 - exp(-2 dt / tau))).
    const double sigma = params_.dynamic_bias_stddev, tau = params_.dynamic_bias_correlation_time;
    const double step = std::sqrt(-sigma * sigma * tau / 2 * std::expm1(-2 * elapsed_s / tau));
    bias_ = std::exp(-elapsed_s / tau) * bias_ + step * drift_(random);
  }
  double out = value + bias_ + white_noise;
  if (params_.precision > 0) out = std::round(out / params_.precision) * params_.precision;
  return out;
}

}  // namespace onedof_sim::plugins
