#include "radar/radar_detect.h"

#include <algorithm>
#include <cmath>

#include "nav_sensors/noise.h"

namespace convoy::radar {

namespace {

using nav_sensors::random_bits;
using nav_sensors::standard_normal;

constexpr uint64_t kStream = 0x524144;         // "RAD"
constexpr uint64_t kClutterStream = 0x434c54;  // "CLT"
constexpr double kClutterRange = 60;

double uniform(uint64_t key, uint64_t stream, uint64_t k) {
  return (random_bits(key, stream, k) >> 11) * 0x1.0p-53;
}

// A Poisson count of mean `mean` by inversion of one uniform draw.
int poisson(double mean, double u) {
  double p = std::exp(-mean), cdf = p;
  int n = 0;
  while (u > cdf && n < 10000) {
    ++n;
    p *= mean / n;
    cdf += p;
    if (p <= 0) break;
  }
  return n;
}

double azimuth_of(const Eigen::Vector3d& c) { return std::atan2(c.y(), c.x()); }
double elevation_of(const Eigen::Vector3d& c) {
  return std::atan2(c.z(), std::hypot(c.x(), c.y()));
}

// The detection draw (a false return has passed the threshold already), then noise; false if
// missed.
bool measure(const RadarParams& p, uint64_t key, uint64_t stream, bool draw, Detection& d) {
  auto n = [&](uint64_t k) { return standard_normal(key, stream, k); };
  d.snr = snr_db(p, d.rcs, d.range);
  if (draw && uniform(key, stream, 100) >= detection_probability(d.snr)) return false;
  d.range = std::max(0.0, d.range + p.range_stddev * n(0));
  d.azimuth += p.azimuth_stddev * n(2);
  d.elevation += p.elevation_stddev * n(4);
  d.range_rate += p.range_rate_stddev * n(6);
  d.rcs += p.rcs_stddev * n(8);
  return d.range >= p.min_range && d.range <= p.max_range;
}

void add_clutter(const RadarParams& p, const Eigen::Vector3d& v, uint64_t key,
                 std::vector<Detection>& out) {
  if (p.clutter <= 0) return;
  const int count = poisson(p.clutter, uniform(key, kClutterStream, 0));
  const double far = std::min(p.max_range, std::max(p.min_range + 1, kClutterRange));
  for (int i = 0; i < count; ++i) {
    const uint64_t s = kClutterStream + 1 + static_cast<uint64_t>(i);
    Detection d;
    d.clutter = true;
    d.range = p.min_range + (far - p.min_range) * uniform(key, s, 10);
    d.azimuth = (uniform(key, s, 11) - 0.5) * p.horizontal_fov;
    d.elevation = -0.5 * p.vertical_fov * uniform(key, s, 12);
    d.rcs = -15 + 10 * uniform(key, s, 13);
    const Eigen::Vector3d u(std::cos(d.elevation) * std::cos(d.azimuth),
                            std::cos(d.elevation) * std::sin(d.azimuth), std::sin(d.elevation));
    d.range_rate = -v.dot(u);
    if (measure(p, key, s, /*draw=*/false, d)) out.push_back(d);
  }
}

}  // namespace

bool in_view(const RadarParams& p, const Eigen::Vector3d& c) {
  const double r = c.norm();
  return r >= p.min_range && r <= p.max_range &&
         std::abs(azimuth_of(c)) <= 0.5 * p.horizontal_fov &&
         std::abs(elevation_of(c)) <= 0.5 * p.vertical_fov;
}

std::vector<Detection> detect(const RadarParams& p, const std::vector<Target>& targets,
                              const Eigen::Vector3d& sensor_velocity, uint64_t seed,
                              int64_t time_ns) {
  const uint64_t key = random_bits(seed, kStream, static_cast<uint64_t>(time_ns));
  std::vector<Detection> out;
  for (const Target& t : targets) {
    if (t.visible_fraction <= 0 || !in_view(p, t.centre)) continue;
    Detection d;
    d.id = t.id;
    d.range = t.range >= 0 ? t.range : t.centre.norm();
    d.azimuth = azimuth_of(t.centre);
    d.elevation = elevation_of(t.centre);
    d.range_rate = t.velocity.dot(t.centre.normalized());
    d.rcs = rcs_dbsm(t.cls, t.size.x(), t.size.y(), t.size.z()) +
            10 * std::log10(std::min(1.0, t.visible_fraction));
    // streams of targets: their ids (kept apart from clutter's by the top bit)
    if (measure(p, key, (uint64_t{1} << 63) | t.id, /*draw=*/true, d)) out.push_back(d);
  }
  add_clutter(p, sensor_velocity, key, out);
  std::sort(out.begin(), out.end(), [](const Detection& a, const Detection& b) {
    return a.range != b.range ? a.range < b.range : a.id < b.id;
  });
  return out;
}

}  // namespace convoy::radar
