#include "nav_sensors/noise.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace convoy::nav_sensors {

namespace {

uint64_t mix(uint64_t z) {  // splitmix64's finaliser
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

double unit(uint64_t h) {  // (0, 1]
  return (static_cast<double>(h >> 11) + 1.0) * (1.0 / 9007199254740992.0);
}

void require_non_negative(const char* field, double v) {
  if (!(v >= 0) || !std::isfinite(v))
    throw std::invalid_argument(std::string(field) + ": " + std::to_string(v) +
                                " is not a finite non-negative number");
}

}  // namespace

NoiseParams::Type noise_type(const std::string& name) {
  if (name == "none" || name.empty()) return NoiseParams::Type::none;
  if (name == "gaussian") return NoiseParams::Type::gaussian;
  if (name == "gaussian_quantized") return NoiseParams::Type::gaussian_quantized;
  throw std::invalid_argument("type: '" + name +
                              "' is not a noise type (none, gaussian, gaussian_quantized)");
}

void check(const NoiseParams& p) {
  if (!std::isfinite(p.mean)) throw std::invalid_argument("mean: not a finite number");
  if (!std::isfinite(p.bias_mean)) throw std::invalid_argument("bias_mean: not a finite number");
  require_non_negative("stddev", p.stddev);
  require_non_negative("bias_stddev", p.bias_stddev);
  require_non_negative("dynamic_bias_stddev", p.dynamic_bias_stddev);
  require_non_negative("dynamic_bias_correlation_time", p.dynamic_bias_correlation_time);
  require_non_negative("precision", p.precision);
}

uint64_t random_bits(uint64_t seed, uint64_t stream, uint64_t index) {
  return mix(mix(seed ^ 0x9e3779b97f4a7c15ULL) ^ mix(stream + 0x632be59bd9b4e019ULL) ^
             (index * 0xd1b54a32d192ed03ULL));
}

double standard_normal(uint64_t seed, uint64_t stream, uint64_t index) {
  const uint64_t h = random_bits(seed, stream, index);
  const double u1 = unit(h), u2 = unit(mix(h + 1));
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

NoiseChannel::NoiseChannel(const NoiseParams& params, uint64_t seed, uint64_t stream)
    : p_(params), seed_(seed), stream_(stream) {
  check(p_);
  reset();
}

void NoiseChannel::reset() {
  index_ = 0;
  dynamic_bias_ = 0;
  bias_ = 0;
  if (!p_.active()) return;
  bias_ = p_.bias_mean + p_.bias_stddev * draw();
  if (random_bits(seed_, stream_, index_++) & 1) bias_ = -bias_;
}

double NoiseChannel::apply(double value, double dt) {
  if (!p_.active()) return value;
  const double s = p_.dynamic_bias_stddev, tau = p_.dynamic_bias_correlation_time;
  if (s > 0 && tau > 0) {
    const double phi = std::exp(-std::max(dt, 0.0) / tau);
    dynamic_bias_ = phi * dynamic_bias_ + s * std::sqrt(1 - phi * phi) * draw();
  }
  double out = value + p_.mean + bias_ + dynamic_bias_ + p_.stddev * draw();
  if (p_.type == NoiseParams::Type::gaussian_quantized && p_.precision > 0)
    out = std::round(out / p_.precision) * p_.precision;
  return out;
}

}  // namespace convoy::nav_sensors
