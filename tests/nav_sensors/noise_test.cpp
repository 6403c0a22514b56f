// Unit tests of src/nav_sensors/noise.*: SDF's <noise> statistics, determinism and checks.
#include "nav_sensors/noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <stdexcept>
#include <vector>

using convoy::nav_sensors::NoiseChannel;
using convoy::nav_sensors::NoiseParams;

namespace {

struct Stats {
  double mean = 0, stddev = 0;
};

Stats stats(const std::vector<double>& v) {
  Stats s;
  for (double x : v) s.mean += x;
  s.mean /= static_cast<double>(v.size());
  for (double x : v) s.stddev += (x - s.mean) * (x - s.mean);
  s.stddev = std::sqrt(s.stddev / static_cast<double>(v.size() - 1));
  return s;
}

std::vector<double> samples(NoiseChannel& c, int n, double dt = 0.01, double value = 0) {
  std::vector<double> out;
  for (int i = 0; i < n; ++i) out.push_back(c.apply(value, dt));
  return out;
}

NoiseParams gaussian(double mean, double stddev) {
  NoiseParams p;
  p.type = NoiseParams::Type::gaussian;
  p.mean = mean;
  p.stddev = stddev;
  return p;
}

}  // namespace

TEST(Noise, NoneLeavesTheValue) {
  NoiseChannel c(NoiseParams{}, 1, 0);
  EXPECT_EQ(c.apply(3.25, 0.1), 3.25);
}

TEST(Noise, GaussianHasItsMeanAndDeviation) {
  NoiseChannel c(gaussian(0.5, 0.2), 7, 3);
  const Stats s = stats(samples(c, 40000, 0.01, 10.0));
  EXPECT_NEAR(s.mean, 10.5, 0.01);
  EXPECT_NEAR(s.stddev, 0.2, 0.005);
}

TEST(Noise, ConstantBiasHasItsSizeAndEitherSign) {
  NoiseParams p = gaussian(0, 0);
  p.bias_mean = 0.3;
  std::set<double> biases;
  for (uint64_t seed = 0; seed < 32; ++seed) {
    NoiseChannel c(p, seed, 0);
    EXPECT_DOUBLE_EQ(std::abs(c.bias()), 0.3);
    EXPECT_DOUBLE_EQ(c.apply(1.0, 0.01), 1.0 + c.bias());
    biases.insert(c.bias());
  }
  EXPECT_EQ(biases.size(), 2u);  // both signs among 32 seeds
}

TEST(Noise, DynamicBiasWandersWithItsDeviationAndCorrelationTime) {
  NoiseParams p = gaussian(0, 0);
  p.dynamic_bias_stddev = 0.1;
  p.dynamic_bias_correlation_time = 2.0;
  NoiseChannel c(p, 11, 0);
  const double dt = 0.05;
  const std::vector<double> v = samples(c, 200000, dt);
  EXPECT_NEAR(stats(v).stddev, 0.1, 0.01);
  double num = 0, den = 0;  // lag-1 autocorrelation: e^(-dt/tau)
  for (size_t i = 1; i < v.size(); ++i) num += v[i] * v[i - 1];
  for (double x : v) den += x * x;
  EXPECT_NEAR(num / den, std::exp(-dt / 2.0), 0.003);
}

TEST(Noise, QuantizedReadingsAreMultiplesOfThePrecision) {
  NoiseParams p = gaussian(0, 0.3);
  p.type = NoiseParams::Type::gaussian_quantized;
  p.precision = 0.25;
  NoiseChannel c(p, 5, 1);
  for (double x : samples(c, 1000, 0.01, 1.1)) EXPECT_DOUBLE_EQ(std::fmod(x / 0.25, 1.0), 0.0);
}

TEST(Noise, SameSeedSameReadingsAndResetRepeats) {
  NoiseParams p = gaussian(0, 1);
  p.bias_stddev = 0.5;
  NoiseChannel a(p, 42, 2), b(p, 42, 2), other(p, 43, 2), stream(p, 42, 3);
  const auto va = samples(a, 100);
  EXPECT_EQ(va, samples(b, 100));
  EXPECT_NE(va, samples(other, 100));
  EXPECT_NE(va, samples(stream, 100));
  a.reset();
  EXPECT_EQ(va, samples(a, 100));
}

TEST(Noise, BadParametersNameTheField) {
  NoiseParams p = gaussian(0, -1);
  try {
    NoiseChannel c(p, 0, 0);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("stddev"), std::string::npos) << e.what();
  }
  EXPECT_THROW(convoy::nav_sensors::noise_type("uniform"), std::invalid_argument);
  EXPECT_EQ(convoy::nav_sensors::noise_type("gaussian_quantized"),
            NoiseParams::Type::gaussian_quantized);
}
