// The one noise model of every sensor and plugin: Gazebo's, as its NoiseFactory reads a
// <noise> element and its GaussianNoiseModel adds it.
//
// Types: none, gaussian and gaussian_quantized (one model; Gazebo keeps the second name for
// compatibility). A bias is drawn once, when the model is made: N(bias_mean, bias_stddev), of
// either sign with equal chance. Each value then gets the bias and N(mean, stddev), and is rounded
// to a multiple of precision when precision > 0 (for either type, as Gazebo rounds). With
// dynamic_bias_stddev and dynamic_bias_correlation_time both > 0, the bias drifts between
// values as a first-order Gauss-Markov process over the sim time the caller gives (SDF's
// meaning, as gz-sensors applies it; Gazebo classic reads the two and applies nothing). The
// gazebo_ros plugins' older <gaussianNoise> is the same model with stddev alone (whiteNoise).
//
// Every draw comes from a generator the caller owns, seeded with seedOf(its scoped name), so that
// runs in lock-step repeat their noise (Gazebo seeds its generator at random).
#pragma once

#include <cstdint>
#include <random>
#include <string>

#include <tinyxml2.h>

namespace onedof_sim::plugins {

// The generator every noise draws from, one for each sensor or plugin.
using NoiseRandom = std::mt19937_64;

// FNV-1a of `text`: a generator's seed that is the same on every run and machine.
uint64_t seedOf(const std::string& text);

struct NoiseParams {
  bool on = false;  // gaussian or gaussian_quantized; off: none
  double mean = 0, stddev = 0;
  double bias_mean = 0, bias_stddev = 0;
  double dynamic_bias_stddev = 0, dynamic_bias_correlation_time = 0;  // s
  double precision = 0;  // > 0: each value rounded to a multiple of it

  bool drifts() const { return on && dynamic_bias_stddev > 0 && dynamic_bias_correlation_time > 0; }
};

// gazebo_ros' <gaussianNoise>: N(0, stddev) on each value; none when stddev is 0.
NoiseParams whiteNoise(double stddev);

// Reads `noise` (a <noise> element; null: none) into *params. The type is the attribute (SDF 1.5
// and later) or a <type> child (SDF 1.4). False, with *error naming `where` ("<ray><noise>"),
// when the type is not one simulated, a number is malformed or a deviation, time or precision
// is negative.
bool readNoise(const tinyxml2::XMLElement* noise, const std::string& where, NoiseParams* params,
               std::string* error);

class NoiseModel {
 public:
  NoiseModel() = default;  // none
  // Draws the bias from `random` (nothing is drawn when bias_mean and bias_stddev are 0).
  NoiseModel(const NoiseParams& params, NoiseRandom& random);

  // `value` with the noise added. `elapsed_s` > 0: the sim time since the last value, over which
  // a dynamic bias drifts first (0: it does not drift). Nothing is drawn when the model is none.
  double apply(double value, NoiseRandom& random, double elapsed_s = 0);
  // One N(mean, stddev) deviate alone, no bias nor rounding: the image noise of Gazebo's cameras,
  // which takes the mean and stddev only.
  double white(NoiseRandom& random);

  bool on() const { return params_.on; }
  double bias() const { return bias_; }
  const NoiseParams& params() const { return params_; }

 private:
  NoiseParams params_;
  double bias_ = 0;
  std::normal_distribution<double> white_;   // N(mean, stddev)
  std::normal_distribution<double> drift_;   // N(0, 1), scaled for the drift's step
};

}  // namespace onedof_sim::plugins
