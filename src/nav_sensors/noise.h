// SDF's <noise> for one scalar channel (sdformat's Noise, as Gazebo's sensors apply it):
// a constant bias drawn once per sensor, a slowly wandering bias (a first-order Gauss-Markov
// process), white Gaussian noise every sample, and optional quantisation.
//
//   reading = value + mean + bias + dynamic_bias(t) + N(0, stddev), rounded to `precision`
//
// bias: drawn at construction (and reset) from N(bias_mean, bias_stddev), its sign flipped
// with probability 1/2 (so a bias_mean says how large, not which way). dynamic_bias: starts
// at 0; after a sample dt seconds later b <- b e^(-dt/tau) + N(0, s^2 (1 - e^(-2 dt/tau))),
// whose stationary standard deviation is s = dynamic_bias_stddev, tau the correlation time
// (none when either is 0). Quantisation: type "gaussian_quantized" with precision > 0.
//
// Every draw comes from a counter-based generator (seed, channel, sample index), so a
// reading depends only on the seed and what came before on its own channel: a run with the
// same seed reads the same, whatever else the world engine does.
#pragma once

#include <cstdint>
#include <string>

namespace convoy::nav_sensors {

struct NoiseParams {
  enum class Type { none, gaussian, gaussian_quantized };
  Type type = Type::none;
  double mean = 0, stddev = 0;
  double bias_mean = 0, bias_stddev = 0;
  double dynamic_bias_stddev = 0, dynamic_bias_correlation_time = 0;
  double precision = 0;

  bool active() const { return type != Type::none; }
};

// "none", "gaussian", "gaussian_quantized"; throws std::invalid_argument for other names.
NoiseParams::Type noise_type(const std::string& name);
// Throws std::invalid_argument naming the field ("stddev: -1 is negative") for a bad value.
void check(const NoiseParams& p);

// 64 random bits: a pure function of (seed, stream, index).
uint64_t random_bits(uint64_t seed, uint64_t stream, uint64_t index);
// A standard normal draw: a pure function of (seed, stream, index).
double standard_normal(uint64_t seed, uint64_t stream, uint64_t index);

class NoiseChannel {
 public:
  NoiseChannel() = default;
  // `stream` tells channels of one seed apart (one per axis and quantity of a sensor).
  NoiseChannel(const NoiseParams& params, uint64_t seed, uint64_t stream);

  // The reading of `value`, `dt` seconds after the previous sample (the first: any dt).
  double apply(double value, double dt);
  // Back to the state after construction (the same constant bias).
  void reset();

  double bias() const { return bias_; }
  double dynamic_bias() const { return dynamic_bias_; }

 private:
  double draw() { return standard_normal(seed_, stream_, index_++); }

  NoiseParams p_;
  uint64_t seed_ = 0, stream_ = 0, index_ = 0;
  double bias_ = 0, dynamic_bias_ = 0;
};

}  // namespace convoy::nav_sensors
