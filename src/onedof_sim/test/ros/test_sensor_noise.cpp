// The one noise model (src/ros/sensors/sensor_noise.h), no roscore: its statistics over many
// draws from a fixed seed (mean, stddev, the bias and its sign, precision, the dynamic bias's
// stationary spread and correlation), that a seed repeats its draws, and how a <noise> element
// is read.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <tinyxml2.h>

#include "sensors/sensor_noise.h"

namespace onedof_sim::plugins {
namespace {

struct Moments {
  double mean = 0, stddev = 0;
};

Moments moments(const std::vector<double>& values) {
  Moments m;
  for (double v : values) m.mean += v;
  m.mean /= values.size();
  for (double v : values) m.stddev += (v - m.mean) * (v - m.mean);
  m.stddev = std::sqrt(m.stddev / (values.size() - 1));
  return m;
}

std::vector<double> draws(NoiseModel* model, NoiseRandom* random, double value, int count,
                          double elapsed_s = 0) {
  std::vector<double> out;
  for (int i = 0; i < count; ++i) out.push_back(model->apply(value, *random, elapsed_s));
  return out;
}

NoiseParams gaussian(double mean, double stddev) {
  NoiseParams p;
  p.on = true;
  p.mean = mean;
  p.stddev = stddev;
  return p;
}

// Reads `xml` (a <noise> element) with readNoise.
bool read(const std::string& xml, NoiseParams* params, std::string* error) {
  tinyxml2::XMLDocument doc;
  EXPECT_EQ(doc.Parse(xml.c_str()), tinyxml2::XML_SUCCESS) << xml;
  return readNoise(doc.RootElement(), "<ray><noise>", params, error);
}

constexpr int kDraws = 200000;

TEST(SensorNoise, GaussianHasItsMeanAndStddev) {
  NoiseRandom random(seedOf("statistics"));
  NoiseModel model(gaussian(0.25, 0.5), random);
  EXPECT_EQ(model.bias(), 0.0);
  const Moments m = moments(draws(&model, &random, 10.0, kDraws));
  // Five standard errors: the mean's stddev / sqrt(n), the stddev's stddev / sqrt(2 n).
  EXPECT_NEAR(m.mean, 10.25, 5 * 0.5 / std::sqrt(kDraws));
  EXPECT_NEAR(m.stddev, 0.5, 5 * 0.5 / std::sqrt(2.0 * kDraws));
}

TEST(SensorNoise, ABiasIsDrawnOnceWithEitherSignAndAddsToEveryValue) {
  NoiseParams p = gaussian(0, 0.1);
  p.bias_mean = 2.0;
  p.bias_stddev = 0.05;
  std::vector<double> biases;
  int negative = 0;
  constexpr int kModels = 4000;
  for (int i = 0; i < kModels; ++i) {
    NoiseRandom random(seedOf("bias " + std::to_string(i)));
    NoiseModel model(p, random);
    biases.push_back(std::abs(model.bias()));
    if (model.bias() < 0) ++negative;
    if (i == 0) {
      // Every value of one model carries its one bias.
      const Moments m = moments(draws(&model, &random, 1.0, kDraws));
      EXPECT_NEAR(m.mean, 1.0 + model.bias(), 5 * 0.1 / std::sqrt(kDraws));
      EXPECT_NEAR(m.stddev, 0.1, 5 * 0.1 / std::sqrt(2.0 * kDraws));
    }
  }
  // Either sign with equal chance: a binomial of kModels, within five of its standard deviations.
  EXPECT_NEAR(negative, kModels / 2, 5 * std::sqrt(kModels * 0.25));
  const Moments size = moments(biases);
  EXPECT_NEAR(size.mean, 2.0, 5 * 0.05 / std::sqrt(kModels));
  EXPECT_NEAR(size.stddev, 0.05, 5 * 0.05 / std::sqrt(2.0 * kModels));
}

TEST(SensorNoise, PrecisionRoundsEveryValueToAMultiple) {
  NoiseParams p = gaussian(0, 0.3);
  p.precision = 0.25;
  NoiseRandom random(seedOf("precision"));
  NoiseModel model(p, random);
  const std::vector<double> values = draws(&model, &random, 3.1, kDraws);
  bool off_grid = false;
  for (double v : values) off_grid = off_grid || std::abs(v / 0.25 - std::round(v / 0.25)) > 1e-9;
  EXPECT_FALSE(off_grid);
  // Rounding to a grid finer than the spread keeps the mean; it adds a uniform error of
  // precision^2 / 12 to the variance.
  const Moments m = moments(values);
  EXPECT_NEAR(m.mean, 3.1, 5 * 0.3 / std::sqrt(kDraws));
  EXPECT_NEAR(m.stddev, std::sqrt(0.09 + 0.0625 / 12), 5 * 0.3 / std::sqrt(2.0 * kDraws));
}

TEST(SensorNoise, NoneAndAZeroStddevDrawNothing) {
  NoiseRandom random(seedOf("nothing"));
  const NoiseRandom before = random;
  NoiseModel none(NoiseParams{}, random);
  EXPECT_EQ(none.apply(1.5, random), 1.5);
  NoiseModel constant(gaussian(0.5, 0), random);
  EXPECT_EQ(constant.apply(1.5, random), 2.0);
  NoiseModel white(whiteNoise(0), random);
  EXPECT_FALSE(white.on());
  EXPECT_EQ(white.apply(1.5, random), 1.5);
  EXPECT_TRUE(random == before);
}

TEST(SensorNoise, AFixedSeedRepeatsItsDraws) {
  NoiseParams p = gaussian(0.1, 0.2);
  p.bias_mean = 0.3;
  p.bias_stddev = 0.1;
  p.dynamic_bias_stddev = 0.05;
  p.dynamic_bias_correlation_time = 2;
  auto run = [&](const std::string& name) {
    NoiseRandom random(seedOf(name));
    NoiseModel model(p, random);
    return draws(&model, &random, 0.0, 1000, 0.01);
  };
  EXPECT_EQ(run("model::link::sensor"), run("model::link::sensor"));
  EXPECT_NE(run("model::link::sensor"), run("model::link::other"));
  EXPECT_EQ(seedOf("model::link::sensor"), seedOf("model::link::sensor"));
  EXPECT_NE(seedOf("a"), seedOf("b"));
}

TEST(SensorNoise, GaussianNoiseOfThePluginsIsWhiteWithItsStddev) {
  NoiseRandom random(seedOf("gaussianNoise"));
  NoiseModel model(whiteNoise(0.02), random);
  EXPECT_TRUE(model.on());
  const Moments m = moments(draws(&model, &random, -4.0, kDraws));
  EXPECT_NEAR(m.mean, -4.0, 5 * 0.02 / std::sqrt(kDraws));
  EXPECT_NEAR(m.stddev, 0.02, 5 * 0.02 / std::sqrt(2.0 * kDraws));
}

TEST(SensorNoise, ADynamicBiasDriftsAsAGaussMarkovProcess) {
  NoiseParams p = gaussian(0, 0);
  p.dynamic_bias_stddev = 0.2;
  p.dynamic_bias_correlation_time = 0.5;  // s
  constexpr double kDt = 0.01;            // s between values
  NoiseRandom random(seedOf("drift"));
  NoiseModel model(p, random);
  // Without elapsed time the bias stands still.
  EXPECT_EQ(model.apply(0, random), 0.0);
  EXPECT_EQ(model.apply(0, random, 0), 0.0);
  draws(&model, &random, 0, 2000, kDt);  // ten correlation times: the start forgotten
  const std::vector<double> bias = draws(&model, &random, 0, 2000000, kDt);
  // Stationary: variance sigma^2 tau / 2; neighbours correlated by exp(-dt / tau). About
  // 2000000 dt / (2 tau) = 20000 independent stretches: the variance within 10 %.
  const Moments m = moments(bias);
  const double spread = 0.2 * std::sqrt(0.5 / 2);
  EXPECT_NEAR(m.mean, 0, 5 * spread / std::sqrt(20000.0));
  EXPECT_NEAR(m.stddev, spread, 0.1 * spread);
  double lag = 0;
  for (size_t i = 1; i < bias.size(); ++i) lag += (bias[i] - m.mean) * (bias[i - 1] - m.mean);
  lag /= (bias.size() - 1) * m.stddev * m.stddev;
  EXPECT_NEAR(lag, std::exp(-kDt / 0.5), 0.002);
}

TEST(SensorNoise, ReadsTheNoiseElement) {
  NoiseParams p;
  std::string error;
  ASSERT_TRUE(read("<noise type='gaussian'><mean>0.1</mean><stddev> 0.2 </stddev>"
                   "<bias_mean>0.3</bias_mean><bias_stddev>0.4</bias_stddev>"
                   "<dynamic_bias_stddev>0.5</dynamic_bias_stddev>"
                   "<dynamic_bias_correlation_time>60</dynamic_bias_correlation_time>"
                   "<precision>0.01</precision></noise>",
                   &p, &error))
      << error;
  EXPECT_TRUE(p.on);
  EXPECT_EQ(p.mean, 0.1);
  EXPECT_EQ(p.stddev, 0.2);
  EXPECT_EQ(p.bias_mean, 0.3);
  EXPECT_EQ(p.bias_stddev, 0.4);
  EXPECT_EQ(p.dynamic_bias_stddev, 0.5);
  EXPECT_EQ(p.dynamic_bias_correlation_time, 60);
  EXPECT_EQ(p.precision, 0.01);
  EXPECT_TRUE(p.drifts());
  // SDF 1.4: <type> inside; gaussian_quantized is gaussian.
  ASSERT_TRUE(read("<noise><type> gaussian_quantized </type><stddev>1</stddev></noise>", &p,
                   &error));
  EXPECT_TRUE(p.on);
  EXPECT_EQ(p.stddev, 1);
  EXPECT_FALSE(p.drifts());
  ASSERT_TRUE(read("<noise type='none'><stddev>1</stddev></noise>", &p, &error));
  EXPECT_FALSE(p.on);
  ASSERT_TRUE(readNoise(nullptr, "<ray><noise>", &p, &error));
  EXPECT_FALSE(p.on);
}

TEST(SensorNoise, RefusesAMalformedNoiseElementNamingIt) {
  NoiseParams p;
  std::string error;
  EXPECT_FALSE(read("<noise type='uniform'/>", &p, &error));
  EXPECT_EQ(error, "<ray><noise> has type 'uniform': only gaussian, gaussian_quantized and none "
                   "are simulated (custom needs a plugin's own noise callback, which none here "
                   "sets)");
  EXPECT_FALSE(read("<noise><stddev>1</stddev></noise>", &p, &error));
  EXPECT_EQ(error, "<ray><noise> has no type (gaussian, gaussian_quantized or none)");
  EXPECT_FALSE(read("<noise type='gaussian'><stddev>abc</stddev></noise>", &p, &error));
  EXPECT_EQ(error, "<ray><noise><stddev> is 'abc', not a number");
  EXPECT_FALSE(read("<noise type='gaussian'><precision>-1</precision></noise>", &p, &error));
  EXPECT_EQ(error, "<ray><noise> has a negative stddev, bias_stddev, dynamic_bias_stddev, "
                   "dynamic_bias_correlation_time or precision");
  EXPECT_FALSE(p.on);  // left as none
}

}  // namespace
}  // namespace onedof_sim::plugins
