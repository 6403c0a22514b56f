#include "camera_sensors.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <numbers>
#include <thread>

#include "datapack/camera.h"
#include "datapack/json.h"
#include "render/mesh_loader.h"
#include "render/readback.h"

namespace convoy::world {

namespace {

render::Pose to_pose(const Eigen::Isometry3d& t) {
  render::Pose p{};
  Eigen::Matrix4d m = t.matrix();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) p[c * 4 + r] = m(r, c);
  return p;
}

render::Material to_material(const Material& m) {
  render::Material out;
  out.diffuse = m.diffuse;
  out.ambient = m.ambient;
  out.specular = m.specular;
  out.emissive = m.emissive;
  return out;
}

bool is_vehicle_class(const std::string& cls) {
  return cls == "car" || cls == "bus" || cls == "truck";
}

// A vehicle's front and ground in the frame of its first link (the one tracked), from its
// collision shapes: how far the front lies ahead (+x), and how high the link's origin is
// above the lowest point (the tyres' contact).
VehicleExtent vehicle_extent(const ModelDesc& model) {
  VehicleExtent e;
  if (model.links.empty()) return e;
  const Eigen::Isometry3d to_first = model.links.front().pose.inverse();
  double front = 0, bottom = 0;
  bool any = false;
  for (const auto& l : model.links)
    for (const auto& c : l.collisions) {
      const Eigen::Isometry3d t = to_first * l.pose * c.pose;
      if (c.shape.kind == Shape::kBox) {
        for (int sx : {-1, 1})
          for (int sy : {-1, 1})
            for (int sz : {-1, 1}) {
              const Eigen::Vector3d p =
                  t * Eigen::Vector3d(sx * c.shape.size.x() / 2, sy * c.shape.size.y() / 2,
                                      sz * c.shape.size.z() / 2);
              front = any ? std::max(front, p.x()) : p.x();
              bottom = any ? std::min(bottom, p.z()) : p.z();
              any = true;
            }
      } else if (c.shape.kind == Shape::kCylinder || c.shape.kind == Shape::kSphere) {
        const Eigen::Vector3d p = t.translation();
        const double r = c.shape.size.x();
        front = any ? std::max(front, p.x() + r) : p.x() + r;
        bottom = any ? std::min(bottom, p.z() - r) : p.z() - r;
        any = true;
      }
    }
  if (any) {
    e.front = front > 0 ? front : 2.0;
    e.height = std::max(0.0, -bottom);
  }
  return e;
}

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

CameraSensors::CameraSensors(const WorldDesc& desc, const PhysicsWorld& physics, uint64_t seed)
    : physics_(physics), rng_(seed) {
  for (const auto& model : desc.models)
    for (const auto& link : model.links)
      for (const auto& cam : link.cameras) {
        Camera c;
        c.desc = &cam;
        c.frame.keep_rgba = true;  // converted (with noise) straight into the datapack
        c.link = physics.link_index(link.name);
        cameras_.push_back(std::move(c));
      }
  if (cameras_.empty()) return;
  // Gaussian noise comes from a fixed table read at a random offset per frame: as random as
  // a camera needs, deterministic for a seed, and far cheaper than a draw per pixel. The tables
  // take about as long as the renderer and the scene, which touch neither rng_ nor the
  // cameras' noise, so they are drawn meanwhile in a thread of their own (the same draws in
  // the same order: the same tables).
  double noise_s = 0;
  std::thread noise([this, &noise_s] {
    const auto start = std::chrono::steady_clock::now();
    std::normal_distribution<double> normal(0.0, 1.0);
    for (auto& cam : cameras_) {
      if (cam.desc->format == "L8" || cam.desc->format == "L_INT8") cam.depth_channels = 1;
      if (!cam.desc->noise || cam.desc->noise_stddev <= 0) continue;
      // 2^20 starting points, each followed by a whole frame's worth of samples
      cam.noise.resize((size_t{1} << 20) +
                       static_cast<size_t>(cam.desc->width) * cam.desc->height * 3);
      for (auto& v : cam.noise) {
        v = static_cast<int16_t>(
            std::lround(255.0 * (cam.desc->noise_mean + cam.desc->noise_stddev * normal(rng_))));
      }
    }
    noise_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  });
  const auto t0 = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point t1, t2;
  try {
    renderer_ = std::make_unique<render::Renderer>();
    t1 = std::chrono::steady_clock::now();
    build_scene(desc);
    t2 = std::chrono::steady_clock::now();
  } catch (...) {
    noise.join();
    throw;
  }
  noise.join();
  auto s = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  std::fprintf(stderr, "convoy: cameras: renderer %.3f s, scene %.3f s, noise %.3f s (alongside)\n",
               s(t0, t1), s(t1, t2), noise_s);
}

CameraSensors::~CameraSensors() = default;

void CameraSensors::build_scene(const WorldDesc& desc) {
  scene_.set_ambient(desc.ambient);
  scene_.set_background(desc.background);
  scene_.set_sky(render::Sky::from_background(desc.background));
  for (const auto& l : desc.lights) {
    render::Light light;
    light.type = l.type == LightDesc::kPoint  ? render::Light::kPoint
                 : l.type == LightDesc::kSpot ? render::Light::kSpot
                                              : render::Light::kDirectional;
    light.position = {static_cast<float>(l.position.x()), static_cast<float>(l.position.y()),
                      static_cast<float>(l.position.z())};
    light.direction = {static_cast<float>(l.direction.x()), static_cast<float>(l.direction.y()),
                       static_cast<float>(l.direction.z())};
    light.diffuse = l.diffuse;
    light.specular = l.specular;
    light.range = static_cast<float>(l.range);
    light.attenuation_constant = static_cast<float>(l.constant);
    light.attenuation_linear = static_cast<float>(l.linear);
    light.attenuation_quadratic = static_cast<float>(l.quadratic);
    if (static_cast<int>(scene_.lights().size()) < render::Scene::kMaxLights) {
      scene_.add_light(light);
      street_light_.push_back(
          l.type != LightDesc::kDirectional &&
          (l.name.rfind("street_light", 0) == 0 || l.name.rfind("lamp", 0) == 0));
    }
  }
  if (desc.lights.empty()) {
    scene_.add_light(render::Light{});
    street_light_.push_back(false);
  }
  base_lights_ = scene_.lights();
  base_ambient_ = desc.ambient;
  base_background_ = desc.background;
  uint32_t model_id = 0;
  for (const auto& model : desc.models) {
    ++model_id;
    model_names_.push_back(model.name);
    model_classes_.push_back(class_of(model));
    // The ground gets no box.
    uint32_t label = is_ground(model) ? 0 : model_id;
    for (auto& cam : cameras_) {
      for (const auto& link : model.links)
        for (const auto& c : link.cameras)
          if (&c == cam.desc) cam.own_model = model_id;
    }
    if (!model.is_static && !model.links.empty() && is_vehicle_class(class_of(model)))
      vehicles_.push_back(
          {model_id, physics_.link_index(model.links.front().name), -1, vehicle_extent(model)});
    for (const auto& link : model.links) {
      Tracked tracked{physics_.link_index(link.name), {}, {}};
      add_visuals(link, link.pose, label, &tracked, /*world=*/true);
      if (!model.is_static && !tracked.instances.empty()) tracked_.push_back(std::move(tracked));
    }
  }
}

const std::vector<CameraSensors::FilePart>& CameraSensors::file_mesh(const std::string& path,
                                                                     const Eigen::Vector3d& scale) {
  char key_scale[96];
  std::snprintf(key_scale, sizeof key_scale, "|%.9g|%.9g|%.9g", scale.x(), scale.y(), scale.z());
  auto [it, fresh] = file_meshes_.try_emplace(path + key_scale);
  if (!fresh) return it->second;
  try {
    for (auto& part :
         render::load_mesh(path, {static_cast<float>(scale.x()), static_cast<float>(scale.y()),
                                  static_cast<float>(scale.z())})) {
      int texture = part.texture_path.empty() ? -1 : scene_.add_texture_file(part.texture_path);
      render::Material material = part.material(texture);
      it->second.push_back(
          {scene_.add_mesh_levels(render::simplified_levels(std::move(part.mesh))), material});
    }
  } catch (...) {
    file_meshes_.erase(it);
    throw;
  }
  return it->second;
}

void CameraSensors::add_visuals(const LinkDesc& link, const Eigen::Isometry3d& placement,
                                uint32_t label, Tracked* tracked, bool world) {
  for (const auto& v : link.visuals) {
    std::vector<std::pair<int, render::Material>> parts;  // Scene mesh, material
    auto one = [this](render::MeshData m) {
      return scene_.add_mesh_levels(render::MeshLevels{{std::move(m)}, {0.0f}});
    };
    Eigen::Isometry3d offset = v.pose;
    render::Material material = to_material(v.material);
    switch (v.shape.kind) {
      case Shape::kBox:
        parts.emplace_back(
            one(render::make_box(v.shape.size.x(), v.shape.size.y(), v.shape.size.z())), material);
        break;
      case Shape::kCylinder: {
        // Tessellation grows with size: thin posts need few segments.
        int segments = std::clamp(static_cast<int>(12 + 20 * v.shape.size.x()), 12, 32);
        parts.emplace_back(scene_.add_mesh_levels(render::cylinder_levels(
                               v.shape.size.x(), v.shape.size.z(), segments)),
                           material);
        break;
      }
      case Shape::kSphere: {
        int stacks = std::clamp(static_cast<int>(8 + 2 * v.shape.size.x()), 8, 16);
        parts.emplace_back(
            scene_.add_mesh_levels(render::sphere_levels(v.shape.size.x(), stacks, 2 * stacks)),
            material);
        break;
      }
      case Shape::kPlane: {
        double sx = v.shape.size.x() > 0 ? v.shape.size.x() : 1000;
        double sy = v.shape.size.y() > 0 ? v.shape.size.y() : 1000;
        Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
        t.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), v.shape.normal)
                         .toRotationMatrix();
        offset = offset * t;
        parts.emplace_back(one(render::make_plane(sx, sy)), material);
        break;
      }
      case Shape::kMesh:
        for (const FilePart& part : file_mesh(v.shape.mesh.string(), v.shape.scale)) {
          render::Material m = v.material.has_material ? material : part.file_material;
          if (v.material.has_material && part.file_material.texture >= 0)
            m.texture = part.file_material.texture;
          parts.emplace_back(part.mesh, m);
        }
        break;
      case Shape::kHeightmap:
        break;  // collisions only: a heightmap visual draws nothing
    }
    if (!v.material.texture.empty()) {
      int texture = scene_.add_texture_file(v.material.texture.string());
      for (auto& p : parts) p.second.texture = texture;
    }
    std::vector<int>* named = world ? &visual_instances_[{link.name, v.name}] : nullptr;
    for (auto& [mesh_index, mat] : parts) {
      int inst = scene_.add_instance(mesh_index, mat, to_pose(placement * offset), label, label);
      if (!v.cast_shadows) scene_.set_casts_shadows(inst, false);
      tracked->instances.push_back(inst);
      tracked->offsets.push_back(to_pose(offset));
      if (named) named->push_back(inst);
    }
  }
}

std::vector<int> CameraSensors::visual_instances(const std::string& link,
                                                 const std::string& visual) const {
  auto it = visual_instances_.find({link, visual});
  return it == visual_instances_.end() ? std::vector<int>{} : it->second;
}

int CameraSensors::add_actor(const ModelDesc& model, const std::string& cls,
                             const std::vector<ModelDesc>& poses) {
  if (cameras_.empty()) return -1;
  model_names_.push_back(model.name);
  model_classes_.push_back(cls);
  const auto label = static_cast<uint32_t>(model_names_.size());
  Actor actor;
  auto add = [&](const ModelDesc& m, int pose) {
    for (const auto& link : m.links) {
      Tracked tracked{-1, {}, {}};
      add_visuals(link, link.pose, label, &tracked);
      actor.instances.insert(actor.instances.end(), tracked.instances.begin(),
                             tracked.instances.end());
      actor.offsets.insert(actor.offsets.end(), tracked.offsets.begin(), tracked.offsets.end());
      actor.link_poses.insert(actor.link_poses.end(), tracked.instances.size(), link.pose);
      actor.pose_of.insert(actor.pose_of.end(), tracked.instances.size(), pose);
    }
  };
  if (poses.empty()) add(model, -1);
  for (size_t k = 0; k < poses.size(); ++k) add(poses[k], static_cast<int>(k));
  for (int inst : actor.instances) scene_.set_visible(inst, false);
  actors_.push_back(std::move(actor));
  const int index = static_cast<int>(actors_.size() - 1);
  if (is_vehicle_class(cls)) vehicles_.push_back({label, -1, index, vehicle_extent(model)});
  return index;
}

void CameraSensors::set_actor_pose(int actor, const Eigen::Isometry3d& pose) {
  if (actor < 0) return;
  Actor& a = actors_[actor];
  a.pose = pose;
  for (size_t k = 0; k < a.instances.size(); ++k)
    scene_.set_pose(a.instances[k], render::compose(to_pose(pose * a.link_poses[k]), a.offsets[k]));
}

void CameraSensors::set_actor_visible(int actor, bool visible) {
  if (actor < 0) return;
  Actor& a = actors_[actor];
  a.visible = visible;
  for (size_t k = 0; k < a.instances.size(); ++k) scene_.set_visible(a.instances[k], shows(a, k));
}

void CameraSensors::set_actor_shown(int actor, int pose) {
  if (actor < 0 || actors_[actor].shown == pose) return;
  Actor& a = actors_[actor];
  a.shown = pose;
  for (size_t k = 0; k < a.instances.size(); ++k) scene_.set_visible(a.instances[k], shows(a, k));
}

void CameraSensors::update(double t) {
  now_ = t;
  if (cameras_.empty()) return;
  bool poses_fresh = false;
  for (auto& cam : cameras_) {
    if (!cam.want_image && !cam.want_depth && !cam.want_boxes) continue;
    // Due from half a physics step before its time: engine clocks in whole nanoseconds (a
    // 1/30 s timestep) fall a little short of the camera's period in doubles.
    if (cam.rendered && t + 0.5 * physics_.step_size() < cam.next_update) continue;
    if (!poses_fresh) {
      for (const auto& tr : tracked_) {
        render::Pose link = to_pose(physics_.link_pose(tr.link));
        for (size_t k = 0; k < tr.instances.size(); ++k)
          scene_.set_pose(tr.instances[k], render::compose(link, tr.offsets[k]));
      }
      poses_fresh = true;
    }
    render(cam);
    const CameraDesc& d = *cam.desc;
    double period = d.update_rate > 0 ? 1.0 / d.update_rate : 0;
    cam.next_update = period > 0 ? std::max(cam.next_update + period, t) : t;
    if (period > 0 && cam.next_update <= t) cam.next_update = t + period;
  }
}

void CameraSensors::render(Camera& cam) {
  const CameraDesc& d = *cam.desc;
  render::CameraSpec spec{d.width, d.height, d.hfov, d.near_clip, d.far_clip};
  const Eigen::Isometry3d camera_pose = physics_.link_pose(cam.link) * d.pose;
  if (has_weather_) apply_weather(cam, camera_pose);
  render::Pose pose = to_pose(camera_pose);
  cam.frame.keep_ids = cam.want_ids;
  renderer_->render(scene_, pose, spec, &cam.frame, cam.want_depth, cam.want_boxes || cam.want_ids);
  ++cam.frames;
  cam.has_depth = cam.want_depth;
  cam.has_boxes = cam.want_boxes || cam.want_ids;
  cam.has_ids = cam.want_ids;
  draw_noise(cam);
  cam.rendered = true;
}

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

void CameraSensors::convert(const Camera& cam, std::span<uint8_t> dst) const {
  // The one copy of a frame in this process: the read-back RGBA, with the noise, into the
  // datapack (in the outgoing shared memory for a large frame). Split in two halves of
  // pixels over two threads: the renderer's wait on the second core.
  const size_t pixels = static_cast<size_t>(cam.frame.width) * cam.frame.height;
  const uint8_t* src = cam.frame.rgba.data();
  const int16_t* noise = cam.noise_at;
  datapack::count_copy(dst.size());
  auto noisy = [&](size_t p, int c) {
    const int v = src[4 * p + c] + noise[3 * p + c];
    return static_cast<uint8_t>(v < 0 ? 0 : v > 255 ? 255 : v);
  };
  if (cam.depth_channels == 1) {
    split_.run(pixels, [&](size_t begin, size_t end) {
      for (size_t p = begin; p < end; ++p) {
        int r = src[4 * p], g = src[4 * p + 1], b = src[4 * p + 2];
        if (noise) r = noisy(p, 0), g = noisy(p, 1), b = noisy(p, 2);
        dst[p] = static_cast<uint8_t>((299 * r + 587 * g + 114 * b + 500) / 1000);
      }
    });
    return;
  }
  // Two passes over each half (RGBA to RGB, then the noise), each a vectorised loop.
  split_.run(
      pixels,
      [&](size_t begin, size_t end) {
        render::rgba_to_rgb(src + 4 * begin, dst.data() + 3 * begin, end - begin);
        if (!noise) return;
        uint8_t* px = dst.data();
        for (size_t i = 3 * begin; i < 3 * end; ++i) {
          const int v = px[i] + noise[i];
          px[i] = static_cast<uint8_t>(v < 0 ? 0 : v > 255 ? 255 : v);
        }
      },
      64);
}

void CameraSensors::image_datapack(size_t i, datapack::Builder& out) {
  Camera& cam = cameras_[i];
  cam.want_image = true;
  if (!cam.rendered) first_render(cam);
  datapack::write_camera(out, static_cast<uint32_t>(cam.frame.height),
                         static_cast<uint32_t>(cam.frame.width),
                         static_cast<uint32_t>(cam.depth_channels),
                         [&](std::span<uint8_t> dst) { convert(cam, dst); });
}

void CameraSensors::depth_datapack(size_t i, datapack::Builder& out) {
  Camera& cam = cameras_[i];
  cam.want_depth = true;
  if (!cam.rendered)
    first_render(cam);
  else if (!cam.has_depth)
    render(cam);  // (noise redrawn: a new sample of the same view)
  const uint64_t shape[2] = {static_cast<uint64_t>(cam.frame.height),
                             static_cast<uint64_t>(cam.frame.width)};
  const std::string_view bytes(reinterpret_cast<const char*>(cam.frame.depth.data()),
                               cam.frame.depth.size() * sizeof(float));
  datapack::write_json(out, {{"width", cam.frame.width},
                             {"height", cam.frame.height},
                             {"depth", datapack::ndarray_json(out, "<f4", shape, bytes)}});
}

namespace {
double visible_fraction(const render::BoundingBox& b) {
  const double full =
      static_cast<double>(b.full_x_max - b.full_x_min) * (b.full_y_max - b.full_y_min);
  const double seen = static_cast<double>(b.x_max - b.x_min + 1) * (b.y_max - b.y_min + 1);
  if (!(full > 0)) return 1.0;
  return std::clamp(seen / full, 0.0, 1.0);
}
}  // namespace

void CameraSensors::instances_datapack(size_t i, datapack::Builder& out) {
  Camera& cam = cameras_[i];
  cam.want_ids = true;
  if (!cam.rendered)
    first_render(cam);
  else if (!cam.has_ids)
    render(cam);
  const size_t pixels = static_cast<size_t>(cam.frame.width) * cam.frame.height;
  ids_.resize(pixels);
  for (size_t p = 0; p < pixels && p < cam.frame.model_ids.size(); ++p) {
    const uint32_t id = cam.frame.model_ids[p];
    ids_[p] = id == cam.own_model ? 0 : id;
  }
  nlohmann::json instances = nlohmann::json::object();
  for (const auto& b : cam.frame.boxes) {
    if (b.model_id == cam.own_model) continue;
    instances[std::to_string(b.model_id)] = {{"model", model_names_[b.model_id - 1]},
                                             {"class", model_classes_[b.model_id - 1]}};
  }
  const uint64_t shape[2] = {static_cast<uint64_t>(cam.frame.height),
                             static_cast<uint64_t>(cam.frame.width)};
  const std::string_view bytes(reinterpret_cast<const char*>(ids_.data()),
                               ids_.size() * sizeof(uint32_t));
  datapack::write_json(out, {{"width", cam.frame.width},
                             {"height", cam.frame.height},
                             {"ids", datapack::ndarray_json(out, "<u4", shape, bytes)},
                             {"instances", instances}});
}

double CameraSensors::visibility(double distance) const {
  if (!has_weather_ || !std::isfinite(weather_.visibility_m) || !std::isfinite(distance))
    return 1.0;
  return std::exp(-3.912 * distance / weather_.visibility_m);
}

void CameraSensors::boxes_datapack(size_t i, datapack::Builder& out) {
  Camera& cam = cameras_[i];
  cam.want_boxes = true;
  if (!cam.rendered)
    first_render(cam);
  else if (!cam.has_boxes)
    render(cam);
  nlohmann::json boxes = nlohmann::json::array();
  for (const auto& b : cam.frame.boxes) {
    if (b.model_id == cam.own_model) continue;  // the camera's own vehicle
    boxes.push_back({{"model", model_names_[b.model_id - 1]},
                     {"class", model_classes_[b.model_id - 1]},
                     {"instance", b.model_id},
                     {"x_min", b.x_min},
                     {"y_min", b.y_min},
                     {"x_max", b.x_max},
                     {"y_max", b.y_max},
                     {"pixels", b.pixel_count},
                     {"distance", std::isfinite(b.distance) ? b.distance : -1.0f},
                     {"visibility", visibility(b.distance)},
                     {"visible_fraction", visible_fraction(b)},
                     {"full_box", {b.full_x_min, b.full_y_min, b.full_x_max, b.full_y_max}}});
  }
  datapack::write_json(
      out, {{"width", cam.frame.width}, {"height", cam.frame.height}, {"boxes", boxes}});
}

}  // namespace convoy::world
