#include "camera_sensors.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <thread>

#include "datapack/camera.h"
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

}  // namespace

CameraSensors::CameraSensors(const WorldDesc& desc, const PhysicsWorld& physics, uint64_t seed,
                             render::MeshFileCache* files, KeptCameras kept)
    : physics_(physics), rng_(seed) {
  if (files) files_ = files;
  for (const auto& model : desc.models)
    for (const auto& link : model.links)
      for (const auto& cam : link.cameras) {
        Camera c;
        c.desc = &cam;
        c.frame.keep_rgba = true;  // converted (with noise) straight into the datapack
        c.link = physics.link_index(link.name);
        cameras_.push_back(std::move(c));
      }
  bool lidars = false;  // a LiDAR scans the same scene (systems/lidar_sensors.h)
  for (const auto& model : desc.models)
    for (const auto& link : model.links)
      lidars = lidars || !link.lidars.empty() || !link.radars.empty();  // radars cast rays too
  if (cameras_.empty() && !lidars) return;
  has_scene_ = true;
  for (auto& cam : cameras_)
    if (cam.desc->format == "L8" || cam.desc->format == "L_INT8") cam.depth_channels = 1;
  // Gaussian noise comes from a fixed table read at a random offset per frame: as random as
  // a camera needs, deterministic for a seed, and far cheaper than a draw per pixel. The tables
  // take about as long as the renderer and the scene, which touch neither rng_ nor the
  // cameras' noise, so they are drawn meanwhile in a thread of their own (the same draws in
  // the same order: the same tables). A world made again takes them, and the renderer, from
  // the last one (`kept`: the same description and seed, so the same tables).
  const bool reuse = kept.has_noise && kept.noise.size() == cameras_.size();
  double noise_s = 0;
  std::thread noise([this, &noise_s, reuse, &kept] {
    const auto start = std::chrono::steady_clock::now();
    if (reuse) {
      for (size_t i = 0; i < cameras_.size(); ++i) cameras_[i].noise = std::move(kept.noise[i]);
      rng_ = kept.rng;
    } else {
      draw_noise_tables();
    }
    rng_after_tables_ = rng_;
    noise_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  });
  const auto t0 = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point t1, t2;
  try {
    if (!cameras_.empty())
      renderer_ = kept.renderer ? std::move(kept.renderer) : std::make_unique<render::Renderer>();
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

void CameraSensors::draw_noise_tables() {
  std::normal_distribution<double> normal(0.0, 1.0);
  for (auto& cam : cameras_) {
    if (!cam.desc->noise || cam.desc->noise_stddev <= 0) continue;
    // 2^20 starting points, each followed by a whole frame's worth of samples
    cam.noise.resize((size_t{1} << 20) +
                     static_cast<size_t>(cam.desc->width) * cam.desc->height * 3);
    for (auto& v : cam.noise) {
      v = static_cast<int16_t>(
          std::lround(255.0 * (cam.desc->noise_mean + cam.desc->noise_stddev * normal(rng_))));
    }
  }
}

KeptCameras CameraSensors::release_kept() {
  KeptCameras k;
  k.renderer = std::move(renderer_);
  for (auto& cam : cameras_) k.noise.push_back(std::move(cam.noise));
  k.rng = rng_after_tables_;
  k.has_noise = has_scene_;
  return k;
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
    for (const auto& part :
         files_->load(path, {static_cast<float>(scale.x()), static_cast<float>(scale.y()),
                             static_cast<float>(scale.z())})) {
      int texture = part.texture_path.empty() ? -1 : scene_.add_texture_file(part.texture_path);
      render::Material material = part.material(texture);
      for (const auto& levels : part.drawables())
        it->second.push_back({scene_.add_mesh_levels(levels), material});
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
  if (!has_scene_) return -1;
  model_names_.push_back(model.name);
  model_classes_.push_back(cls);
  const auto label = static_cast<uint32_t>(model_names_.size());
  Actor actor;
  actor.label = label;
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

// Only the instances shown follow the actor (an animated walker hides all but one pose's),
// and its first, whose pose the radar tracks; the others are posed when they are shown.
void CameraSensors::set_actor_pose(int actor, const Eigen::Isometry3d& pose) {
  if (actor < 0) return;
  Actor& a = actors_[actor];
  a.pose = pose;
  for (size_t k = 0; k < a.instances.size(); ++k)
    if (k == 0 || shows(a, k)) pose_instance(a, k);
}

void CameraSensors::pose_instance(const Actor& a, size_t k) {
  scene_.set_pose(a.instances[k], render::compose(to_pose(a.pose * a.link_poses[k]), a.offsets[k]));
}

void CameraSensors::show_actor(const Actor& a) {
  for (size_t k = 0; k < a.instances.size(); ++k) {
    const bool shown = shows(a, k);
    if (shown && !scene_.instances()[a.instances[k]].visible) pose_instance(a, k);
    scene_.set_visible(a.instances[k], shown);
  }
}

void CameraSensors::set_actor_visible(int actor, bool visible) {
  if (actor < 0) return;
  Actor& a = actors_[actor];
  a.visible = visible;
  show_actor(a);
}

void CameraSensors::set_actor_name(int actor, const std::string& name) {
  if (actor >= 0) model_names_[actors_[actor].label - 1] = name;
}

void CameraSensors::set_actor_shown(int actor, int pose) {
  if (actor < 0 || actors_[actor].shown == pose) return;
  Actor& a = actors_[actor];
  a.shown = pose;
  show_actor(a);
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
      refresh_poses();
      poses_fresh = true;
    }
    render(cam);
    const CameraDesc& d = *cam.desc;
    double period = d.update_rate > 0 ? 1.0 / d.update_rate : 0;
    cam.next_update = period > 0 ? std::max(cam.next_update + period, t) : t;
    if (period > 0 && cam.next_update <= t) cam.next_update = t + period;
  }
}

void CameraSensors::refresh_poses() {
  for (const auto& tr : tracked_) {
    render::Pose link = to_pose(physics_.link_pose(tr.link));
    for (size_t k = 0; k < tr.instances.size(); ++k)
      scene_.set_pose(tr.instances[k], render::compose(link, tr.offsets[k]));
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
  ++frames_rendered_;
  cam.has_depth = cam.want_depth;
  cam.has_boxes = cam.want_boxes || cam.want_ids;
  cam.has_ids = cam.want_ids;
  draw_noise(cam);
  cam.rendered = true;
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
        if (noise) render::add_noise(dst.data() + 3 * begin, noise + 3 * begin, 3 * (end - begin));
      },
      64);
}

}  // namespace convoy::world
