// CameraSensors: the weather in the camera (sun, sky, fog, rain, noise).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "camera_sensors.h"

namespace convoy::world {
namespace {

render::Rgba scaled(const render::Rgba& c, double k) {
  return {static_cast<float>(c[0] * k), static_cast<float>(c[1] * k), static_cast<float>(c[2] * k),
          c[3]};
}

render::Rgba mixed(const render::Rgba& a, const render::Rgba& b, double t) {
  render::Rgba out = a;
  for (int i = 0; i < 3; ++i) out[i] = static_cast<float>(a[i] + (b[i] - a[i]) * t);
  return out;
}

}  // namespace

void CameraSensors::set_weather(const Weather& weather) {
  weather_ = weather;
  has_weather_ = true;
}

void CameraSensors::apply_weather(const Camera& cam, const Eigen::Isometry3d& camera_pose) {
  const Weather& w = weather_;
  const double day = std::clamp(w.daylight, 0.0, 1.0);
  const double fog_amount = std::clamp((1000.0 - w.visibility_m) / 800.0, 0.0, 1.0);
  const double overcast = std::clamp(std::max(1.5 * w.precipitation, fog_amount), 0.0, 1.0);
  // The sun (the world's first directional light) from its altitude and azimuth; dimmed by
  // clouds, gone at night. Other directional lights dim with it.
  scene_.clear_lights();
  const double alt = w.sun_altitude_deg * std::numbers::pi / 180,
               az = w.sun_azimuth_deg * std::numbers::pi / 180;
  const Eigen::Vector3d to_sun(std::cos(alt) * std::sin(az), std::cos(alt) * std::cos(az),
                               std::sin(alt));
  const double sun_scale = day * (1.0 - 0.65 * overcast);
  bool sun_done = false;
  for (size_t i = 0; i < base_lights_.size(); ++i) {
    render::Light l = base_lights_[i];
    if (l.type == render::Light::kDirectional) {
      if (!sun_done) {
        l.direction = {static_cast<float>(-to_sun.x()), static_cast<float>(-to_sun.y()),
                       static_cast<float>(-to_sun.z())};
        sun_done = true;
      }
      if (sun_scale <= 0.001) continue;
      l.diffuse = scaled(l.diffuse, sun_scale);
      l.specular = scaled(l.specular, sun_scale);
    } else if (street_light_[i] && day > 0.5) {
      continue;  // street lights are off by day
    }
    scene_.add_light(l);
  }
  // Headlights at night: the camera's own vehicle (two lamps) and the three nearest others.
  if (w.night) {
    // A lamp 0.7 m above the ground at the vehicle's front, aimed 6 degrees down.
    auto add_lamp = [&](const Eigen::Isometry3d& pose, const VehicleExtent& e, double side) {
      if (static_cast<int>(scene_.lights().size()) >= render::Scene::kMaxLights) return;
      render::Light l;
      l.type = render::Light::kSpot;
      const Eigen::Vector3d p = pose * Eigen::Vector3d(e.front + 0.05, side, 0.7 - e.height);
      const Eigen::Vector3d d = pose.linear() * Eigen::Vector3d(0.995, 0, -0.1).normalized();
      l.position = {static_cast<float>(p.x()), static_cast<float>(p.y()),
                    static_cast<float>(p.z())};
      l.direction = {static_cast<float>(d.x()), static_cast<float>(d.y()),
                     static_cast<float>(d.z())};
      l.diffuse = {3.5f, 3.3f, 3.0f, 1};
      l.specular = {0.3f, 0.3f, 0.3f, 1};
      l.range = 80;
      l.attenuation_constant = 1;
      l.attenuation_linear = 0;
      l.attenuation_quadratic = 0.005f;
      l.spot_inner_angle = 0.35f;
      l.spot_outer_angle = 0.9f;
      l.spot_falloff = 1.0f;
      scene_.add_light(l);
    };
    struct Other {
      double distance;
      VehicleExtent extent;
      Eigen::Isometry3d pose;
    };
    std::vector<Other> others;
    for (const Vehicle& v : vehicles_) {
      Eigen::Isometry3d pose;
      if (v.link >= 0) {
        pose = physics_.link_pose(v.link);
      } else {
        if (!actors_[v.actor].visible) continue;
        pose = actors_[v.actor].pose;
      }
      if (v.model_id == cam.own_model) {
        add_lamp(pose, v.extent, 0.5);
        add_lamp(pose, v.extent, -0.5);
      } else {
        const double d = (pose.translation() - camera_pose.translation()).norm();
        if (d < 80) others.push_back({d, v.extent, pose});
      }
    }
    std::stable_sort(others.begin(), others.end(),
                     [](const Other& a, const Other& b) { return a.distance < b.distance; });
    for (size_t k = 0; k < others.size() && k < 3; ++k)
      add_lamp(others[k].pose, others[k].extent, 0.0);
  }
  // Under clouds the sky's diffuse light makes up for some of the sun's.
  scene_.set_ambient(scaled(base_ambient_, (0.06 + 0.94 * day) * (1.0 + 0.25 * overcast)));
  // The sky: greyer under clouds, dark at night; in fog, the fog's colour.
  const render::Rgba grey{0.6f, 0.62f, 0.65f, 1};
  const render::Rgba sky = scaled(mixed(base_background_, grey, overcast), 0.03 + 0.97 * day);
  const render::Rgba fog = scaled(render::Rgba{0.75f, 0.77f, 0.8f, 1}, 0.04 + 0.96 * day);
  render::Atmosphere a;
  const bool foggy = std::isfinite(w.visibility_m) && w.visibility_m < 1e6;
  a.visibility =
      foggy ? static_cast<float>(w.visibility_m) : std::numeric_limits<float>::infinity();
  a.fog_color = fog;
  a.wetness = static_cast<float>(w.wetness);
  a.snow_cover = static_cast<float>(w.snow_cover);
  a.sky = sky;
  a.precipitation = static_cast<float>(w.precipitation);
  a.snow = w.snow;
  // Drops fall at about 7 m/s, flakes at 1 m/s; the wind across the image slants them.
  const Eigen::Vector3d left = camera_pose.linear() * Eigen::Vector3d::UnitY();
  const double across = -(w.wind_x * left.x() + w.wind_y * left.y());  // towards image right
  a.fall_slant = static_cast<float>(std::clamp(across / (w.snow ? 1.0 : 7.0), -1.5, 1.5));
  a.seed = static_cast<uint32_t>(w.seed ^ (w.seed >> 32));
  a.time = now_;
  scene_.set_atmosphere(a);
  // In fog the sky is the fog's colour but for what 1 km of air lets through.
  const double clear = foggy ? std::exp(-3.912 * 1000.0 / w.visibility_m) : 1.0;
  scene_.set_background(foggy ? mixed(fog, sky, clear) : sky);
  scene_.set_sky(render::Sky::from_background(scene_.background(), static_cast<float>(clear)));
}

void CameraSensors::first_render(Camera& cam) {
  render(cam);
  double rate = cam.desc->update_rate;
  cam.next_update = rate > 0 ? now_ + 1.0 / rate : now_;
}

void CameraSensors::draw_noise(Camera& cam) {
  // Gazebo: each channel value (0..1) gets mean + stddev * N(0, 1), clamped to [0, 1]. The
  // normal samples come from the camera's fixed table, read from a random place each
  // frame: deterministic for a seed, and a loop the compiler vectorises.
  const size_t n = static_cast<size_t>(cam.frame.width) * cam.frame.height * 3;
  cam.noise_at = nullptr;
  if (cam.noise.empty() || cam.noise.size() < n + 1) return;
  const size_t starts = cam.noise.size() - n;
  cam.noise_at = cam.noise.data() + static_cast<size_t>(rng_() % starts);
}

}  // namespace convoy::world
