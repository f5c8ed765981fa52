// A sensor's <noise> element as Gazebo's NoiseFactory reads it (type none, gaussian or
// gaussian_quantized; mean, stddev, bias_mean, bias_stddev, precision) and the noise it adds, as
// Gazebo's GaussianNoiseModel does: a bias drawn once (N(bias_mean, bias_stddev), of either sign
// with equal chance), then for each value N(mean, stddev) and the bias, rounded to a multiple of
// precision when it is > 0. dynamic_bias_stddev and dynamic_bias_correlation_time are read and
// not applied, as in Gazebo classic. The generator is the caller's, seeded so that runs repeat
// (seedOf: the same seed for the same name on every run and machine).
#pragma once

#include <cstdint>
#include <random>
#include <string>

#include <tinyxml2.h>

namespace onedof_sim::plugins {

struct NoiseParams {
  bool on = false;  // gaussian or gaussian_quantized
  double mean = 0, stddev = 0, bias_mean = 0, bias_stddev = 0, precision = 0;
};

// Reads `noise` (a <noise> element; null: no noise). `where` names it in *error. The type is the
// attribute (SDF 1.5 and later) or a <type> child (SDF 1.4).
bool readNoise(const tinyxml2::XMLElement* noise, const std::string& where, NoiseParams* params,
               std::string* error);

class Noise {
 public:
  Noise() = default;
  // Draws the bias from `random`.
  Noise(const NoiseParams& params, std::mt19937_64& random);
  double apply(double value, std::mt19937_64& random) const;

 private:
  NoiseParams params_;
  double bias_ = 0;
};

// The gazebo_ros plugins' <gaussianNoise>: value + sigma * N(0, 1) from the caller's generator;
// nothing is drawn when sigma is 0.
class WhiteNoise {
 public:
  explicit WhiteNoise(double sigma = 0) : sigma_(sigma) {}
  template <class Generator>
  double apply(double value, Generator& random) {
    return sigma_ > 0 ? value + sigma_ * white_(random) : value;
  }

 private:
  double sigma_;
  std::normal_distribution<double> white_{0.0, 1.0};
};

// FNV-1a of `text`: a generator's seed that is the same on every run and machine.
uint64_t seedOf(const std::string& text);

}  // namespace onedof_sim::plugins
