#include "lidar/lidar_sensor.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>

namespace convoy::lidar {

namespace {

constexpr size_t kPacket = 16;
constexpr size_t kBlock = 1024;  // rays a thread takes at a time (a multiple of kPacket)

uint64_t mix(uint64_t x) {  // splitmix64's finaliser
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Uniform in [0, 1) from a ray's stream `h` and draw `k`.
double uniform(uint64_t h, uint64_t k) {
  return (mix(h + k * 0x632be59bd9b4e019ull) >> 11) * 0x1.0p-53;
}

double normal(uint64_t h, uint64_t k) {  // Box-Muller
  const double u1 = 1.0 - uniform(h, k), u2 = uniform(h, k + 1);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

struct Frame {  // a rigid pose in floats: rotation rows and origin
  float r[9], o[3];
  explicit Frame(const render::Pose& p) {
    for (int row = 0; row < 3; ++row)
      for (int c = 0; c < 3; ++c) r[3 * row + c] = static_cast<float>(p[4 * c + row]);
    for (int k = 0; k < 3; ++k) o[k] = static_cast<float>(p[12 + k]);
  }
  void rotate(const float* d, float* w) const {
    for (int k = 0; k < 3; ++k) w[k] = r[3 * k] * d[0] + r[3 * k + 1] * d[1] + r[3 * k + 2] * d[2];
  }
};

struct Hit {
  float t;  // < 0: none
  int instance;
  float cos;
};

// |cos| between the ray and the hit's normal, the normal taken to the world frame.
float incidence(const LidarScene::InstanceInfo& info, const float* ng, const float* dir) {
  const auto& m = info.normal_from_object;
  const float n[3] = {m[0] * ng[0] + m[1] * ng[1] + m[2] * ng[2],
                      m[3] * ng[0] + m[4] * ng[1] + m[5] * ng[2],
                      m[6] * ng[0] + m[7] * ng[1] + m[8] * ng[2]};
  const float nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const float dd = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  if (nn <= 0 || dd <= 0) return 0;
  return std::abs(n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2]) / (nn * dd);
}

// Casts `count` (<= 16) rays with world directions `dirs` (x y z each) from `o`.
void trace(const LidarScene& scene, const float* o, const float* dirs, size_t count, float tnear,
           float tfar, Hit* hits) {
  auto* top = static_cast<RTCScene>(scene.handle());
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  const auto& info = scene.instances();
  if (scene.packets16()) {
    alignas(64) RTCRayHit16 rh;
    alignas(64) int valid[kPacket];
    for (size_t j = 0; j < kPacket; ++j) {
      const bool on = j < count;
      valid[j] = on ? -1 : 0;
      const float* d = dirs + 3 * (on ? j : 0);
      rh.ray.org_x[j] = o[0], rh.ray.org_y[j] = o[1], rh.ray.org_z[j] = o[2];
      rh.ray.dir_x[j] = d[0], rh.ray.dir_y[j] = d[1], rh.ray.dir_z[j] = d[2];
      rh.ray.tnear[j] = tnear, rh.ray.tfar[j] = tfar, rh.ray.time[j] = 0;
      rh.ray.mask[j] = ~0u, rh.ray.id[j] = static_cast<unsigned>(j), rh.ray.flags[j] = 0;
      rh.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][j] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, top, &ctx, &rh);
    for (size_t j = 0; j < count; ++j) {
      if (rh.hit.geomID[j] == RTC_INVALID_GEOMETRY_ID) {
        hits[j] = {-1, -1, 0};
        continue;
      }
      const int inst = static_cast<int>(rh.hit.instID[0][j]);
      const float ng[3] = {rh.hit.Ng_x[j], rh.hit.Ng_y[j], rh.hit.Ng_z[j]};
      hits[j] = {rh.ray.tfar[j], inst, incidence(info[inst], ng, dirs + 3 * j)};
    }
    return;
  }
  for (size_t j = 0; j < count; ++j) {
    RTCRayHit rh;
    const float* d = dirs + 3 * j;
    rh.ray.org_x = o[0], rh.ray.org_y = o[1], rh.ray.org_z = o[2];
    rh.ray.dir_x = d[0], rh.ray.dir_y = d[1], rh.ray.dir_z = d[2];
    rh.ray.tnear = tnear, rh.ray.tfar = tfar, rh.ray.time = 0;
    rh.ray.mask = ~0u, rh.ray.id = 0, rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(top, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
      hits[j] = {-1, -1, 0};
      continue;
    }
    const int inst = static_cast<int>(rh.hit.instID[0]);
    const float ng[3] = {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
    hits[j] = {rh.ray.tfar, inst, incidence(info[inst], ng, d)};
  }
}

}  // namespace

LidarSensor::LidarSensor(const LidarModel& model) : model_(model) {
  model_.validate();
  const int rings = model_.vertical.samples, columns = model_.horizontal.samples;
  dirs_.resize(3 * static_cast<size_t>(rings) * columns);
  for (int r = 0; r < rings; ++r) {
    const double el = model_.vertical.angle(r);
    for (int c = 0; c < columns; ++c) {
      const double az = model_.horizontal.angle(c);
      float* d = &dirs_[3 * (static_cast<size_t>(r) * columns + c)];
      d[0] = static_cast<float>(std::cos(el) * std::cos(az));
      d[1] = static_cast<float>(std::cos(el) * std::sin(az));
      d[2] = static_cast<float>(std::sin(el));
    }
  }
  results_.resize(static_cast<size_t>(rings) * columns);
}

std::array<float, 3> LidarSensor::direction(int ring, int column) const {
  const float* d = &dirs_[3 * (static_cast<size_t>(ring) * model_.horizontal.samples + column)];
  return {d[0], d[1], d[2]};
}

void LidarSensor::cast_block(const LidarScene& scene, const render::Pose& pose, size_t first,
                             size_t count, uint64_t key, const LidarWeather& weather) {
  const Frame frame(pose);
  const auto& info = scene.instances();
  const double alpha = weather.extinction();
  const double spurious = weather.spurious_probability();
  const float tnear = static_cast<float>(model_.range_min);
  const float tfar = static_cast<float>(model_.range_max);
  float world[3 * kPacket];
  Hit hits[kPacket];
  for (size_t at = first; at < first + count; at += kPacket) {
    const size_t n = std::min(kPacket, first + count - at);
    for (size_t j = 0; j < n; ++j) frame.rotate(&dirs_[3 * (at + j)], world + 3 * j);
    trace(scene, frame.o, world, n, tnear, tfar, hits);
    for (size_t j = 0; j < n; ++j) {
      const uint64_t h = mix(key ^ mix(at + j));
      RayResult& out = results_[at + j];
      out = {-1, 0, -1, 0};
      if (hits[j].t >= 0) {
        double range = hits[j].t;
        if (model_.gaussian_noise) range += model_.noise_mean + model_.noise_stddev * normal(h, 0);
        float intensity = info[hits[j].instance].reflectivity * hits[j].cos;
        const WeatherEffect w = attenuate(alpha, range, intensity, uniform(h, 2));
        if (w.kept && range > 0)
          out = {static_cast<float>(range), w.intensity, hits[j].instance, 0};
      }
      if (spurious > 0) {
        const Spurious s = spurious_return(spurious, model_.range_min, uniform(h, 3), uniform(h, 4),
                                           uniform(h, 5));
        const double until = out.range >= 0 ? out.range : model_.range_max;
        if (s.range >= 0 && s.range < until)
          out = {static_cast<float>(s.range), s.intensity, -1, Point::kSpurious};
      }
    }
  }
}

void LidarSensor::scan(const LidarScene& scene, const render::Pose& world_from_sensor, double time,
                       uint64_t seed, const LidarWeather& weather, PointCloud* out) {
  uint64_t time_bits;
  std::memcpy(&time_bits, &time, sizeof time);
  const uint64_t key = mix(mix(seed) ^ time_bits);
  const size_t rays = results_.size();
  const size_t blocks = (rays + kBlock - 1) / kBlock;
  std::atomic<size_t> next{0};
  // Both threads take blocks until none are left: the work is uneven (sky is cheap).
  split_.run(2, [&](size_t, size_t) {
    for (size_t b; (b = next.fetch_add(1)) < blocks;) {
      const size_t first = b * kBlock;
      cast_block(scene, world_from_sensor, first, std::min(kBlock, rays - first), key, weather);
    }
  });
  const int columns = model_.horizontal.samples;
  out->time = time;
  out->rings = model_.vertical.samples;
  out->columns = columns;
  out->points.clear();
  for (size_t i = 0; i < rays; ++i) {
    const RayResult& r = results_[i];
    if (r.range < 0) continue;
    const float* d = &dirs_[3 * i];
    Point p;
    p.x = d[0] * r.range, p.y = d[1] * r.range, p.z = d[2] * r.range;
    p.intensity = std::clamp(r.intensity, 0.0f, 1.0f);
    p.instance = r.instance >= 0 ? scene.instances()[r.instance].model_id : 0;
    p.label = r.instance >= 0 ? scene.instances()[r.instance].class_id : 0;
    p.ring = static_cast<uint16_t>(i / columns);
    p.column = static_cast<uint16_t>(i % columns);
    p.flags = r.flags;
    out->points.push_back(p);
  }
}

}  // namespace convoy::lidar
