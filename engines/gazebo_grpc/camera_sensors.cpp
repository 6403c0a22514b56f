#include "camera_sensors.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>

#include "convoy/datapacks.pb.h"
#include "render/mesh_loader.h"
#include "transport/blobs.h"

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

// A JSON datapack whose "<key>" holds a float32 image as a numpy blob (msgpack ext type 2).
void numpy_blob(nlohmann::json* j, const char* key, const std::vector<float>& values, int h, int w,
                engine::DataPack* out) {
  std::string_view bytes(reinterpret_cast<const char*>(values.data()), values.size() * 4);
  uint32_t index = transport::current_blob_writer().add(out, bytes);
  std::vector<uint8_t> header;
  const std::string dtype = "<f4";
  header.push_back(static_cast<uint8_t>(dtype.size()));
  header.insert(header.end(), dtype.begin(), dtype.end());
  header.push_back(2);
  for (uint64_t d : {static_cast<uint64_t>(h), static_cast<uint64_t>(w)})
    for (int b = 0; b < 8; ++b) header.push_back(static_cast<uint8_t>(d >> (8 * b)));
  for (int b = 3; b >= 0; --b) header.push_back(static_cast<uint8_t>(index >> (8 * b)));
  (*j)[key] = nlohmann::json::binary(header, 2);
}

}  // namespace

std::string CameraSensors::class_of(const std::string& model_name) {
  std::string s = model_name;
  auto scope = s.rfind("::");
  if (scope != std::string::npos) s = s.substr(scope + 2);
  while (!s.empty() && std::isdigit(static_cast<unsigned char>(s.back()))) s.pop_back();
  while (!s.empty() && (s.back() == '_' || s.back() == '-')) s.pop_back();
  return s.empty() ? model_name : s;
}

CameraSensors::CameraSensors(const WorldDesc& desc, const PhysicsWorld& physics, uint64_t seed)
    : physics_(physics), rng_(seed) {
  for (const auto& model : desc.models)
    for (const auto& link : model.links)
      for (const auto& cam : link.cameras) {
        Camera c;
        c.desc = &cam;
        c.link = physics.link_index(link.name);
        cameras_.push_back(std::move(c));
      }
  if (cameras_.empty()) return;
  renderer_ = std::make_unique<render::Renderer>();
  build_scene(desc);
  // Gaussian noise comes from a fixed table read at a random offset per frame: as random as
  // a camera needs, deterministic for a seed, and far cheaper than a draw per pixel.
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
}

CameraSensors::~CameraSensors() = default;

void CameraSensors::build_scene(const WorldDesc& desc) {
  scene_.set_ambient(desc.ambient);
  scene_.set_background(desc.background);
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
    if (static_cast<int>(scene_.lights().size()) < render::Scene::kMaxLights)
      scene_.add_light(light);
  }
  if (desc.lights.empty()) scene_.add_light(render::Light{});
  uint32_t model_id = 0;
  for (const auto& model : desc.models) {
    ++model_id;
    model_names_.push_back(model.name);
    model_classes_.push_back(class_of(model.name));
    // The ground gets no box: a model that shows only planes, or a static one that collides
    // only as planes (a road mesh on a ground plane).
    bool visual_planes = true, collision_planes = true, collides = false;
    for (const auto& link : model.links) {
      for (const auto& v : link.visuals) visual_planes &= v.shape.kind == Shape::kPlane;
      for (const auto& c : link.collisions) {
        collides = true;
        collision_planes &= c.shape.kind == Shape::kPlane;
      }
    }
    bool ground = visual_planes || (model.is_static && collides && collision_planes);
    uint32_t label = ground ? 0 : model_id;
    for (auto& cam : cameras_) {
      for (const auto& link : model.links)
        for (const auto& c : link.cameras)
          if (&c == cam.desc) cam.own_model = model_id;
    }
    for (const auto& link : model.links) {
      Tracked tracked{physics_.link_index(link.name), {}, {}};
      for (const auto& v : link.visuals) {
        std::vector<std::pair<render::MeshLevels, render::Material>> parts;
        auto one = [](render::MeshData m) { return render::MeshLevels{{std::move(m)}, {0.0f}}; };
        Eigen::Isometry3d offset = v.pose;
        render::Material material = to_material(v.material);
        switch (v.shape.kind) {
          case Shape::kBox:
            parts.emplace_back(
                one(render::make_box(v.shape.size.x(), v.shape.size.y(), v.shape.size.z())),
                material);
            break;
          case Shape::kCylinder: {
            // Tessellation grows with size: thin posts need few segments.
            int segments = std::clamp(static_cast<int>(12 + 20 * v.shape.size.x()), 12, 32);
            parts.emplace_back(
                render::cylinder_levels(v.shape.size.x(), v.shape.size.z(), segments), material);
            break;
          }
          case Shape::kSphere: {
            int stacks = std::clamp(static_cast<int>(8 + 2 * v.shape.size.x()), 8, 16);
            parts.emplace_back(render::sphere_levels(v.shape.size.x(), stacks, 2 * stacks),
                               material);
            break;
          }
          case Shape::kPlane: {
            double sx = v.shape.size.x() > 0 ? v.shape.size.x() : 1000;
            double sy = v.shape.size.y() > 0 ? v.shape.size.y() : 1000;
            Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
            t.linear() =
                Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), v.shape.normal)
                    .toRotationMatrix();
            offset = offset * t;
            parts.emplace_back(one(render::make_plane(sx, sy)), material);
            break;
          }
          case Shape::kMesh:
            for (auto& part : render::load_mesh(
                     v.shape.mesh.string(),
                     {static_cast<float>(v.shape.scale.x()), static_cast<float>(v.shape.scale.y()),
                      static_cast<float>(v.shape.scale.z())})) {
              int texture =
                  part.texture_path.empty() ? -1 : scene_.add_texture_file(part.texture_path);
              render::Material m = v.material.has_material ? material : part.material(texture);
              if (v.material.has_material && texture >= 0) m.texture = texture;
              parts.emplace_back(one(std::move(part.mesh)), m);
            }
            break;
        }
        if (!v.material.texture.empty()) {
          int texture = scene_.add_texture_file(v.material.texture.string());
          for (auto& p : parts) p.second.texture = texture;
        }
        for (auto& [mesh, mat] : parts) {
          int mesh_index = scene_.add_mesh_levels(mesh);
          render::Pose world = to_pose(link.pose * offset);
          int inst = scene_.add_instance(mesh_index, mat, world, label,
                                         label ? static_cast<uint32_t>(model_id) : 0);
          tracked.instances.push_back(inst);
          tracked.offsets.push_back(to_pose(offset));
        }
      }
      if (!model.is_static && !tracked.instances.empty()) tracked_.push_back(std::move(tracked));
    }
  }
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
  render::Pose pose = to_pose(physics_.link_pose(cam.link) * d.pose);
  renderer_->render(scene_, pose, spec, &cam.frame, cam.want_depth, cam.want_boxes);
  ++cam.frames;
  cam.has_depth = cam.want_depth;
  cam.has_boxes = cam.want_boxes;
  apply_noise(cam);
  cam.rendered = true;
}

void CameraSensors::first_render(Camera& cam) {
  render(cam);
  double rate = cam.desc->update_rate;
  cam.next_update = rate > 0 ? now_ + 1.0 / rate : now_;
}

void CameraSensors::apply_noise(Camera& cam) {
  // Gazebo: each channel value (0..1) gets mean + stddev * N(0, 1), clamped to [0, 1]. The
  // normal samples come from the camera's fixed table, read from a random place each
  // frame: deterministic for a seed, and a loop the compiler vectorises.
  if (cam.noise.empty()) return;
  const size_t n = cam.frame.rgb.size();
  if (cam.noise.size() < n + 1) return;
  const size_t starts = cam.noise.size() - n;
  uint8_t* px = cam.frame.rgb.data();
  const int16_t* noise = cam.noise.data() + static_cast<size_t>(rng_() % starts);
  for (size_t i = 0; i < n; ++i) {
    int v = px[i] + noise[i];
    px[i] = static_cast<uint8_t>(v < 0 ? 0 : v > 255 ? 255 : v);
  }
}

void CameraSensors::image_datapack(size_t i, engine::DataPack* out) {
  Camera& cam = cameras_[i];
  cam.want_image = true;
  if (!cam.rendered) first_render(cam);
  data::Camera c;
  c.set_image_width(static_cast<uint32_t>(cam.frame.width));
  c.set_image_height(static_cast<uint32_t>(cam.frame.height));
  c.set_image_depth(static_cast<uint32_t>(cam.depth_channels));
  std::string_view bytes(reinterpret_cast<const char*>(cam.frame.rgb.data()), cam.frame.rgb.size());
  std::vector<uint8_t> gray;
  if (cam.depth_channels == 1) {
    gray.resize(cam.frame.rgb.size() / 3);
    for (size_t p = 0; p < gray.size(); ++p) {
      const uint8_t* px = &cam.frame.rgb[3 * p];
      gray[p] = static_cast<uint8_t>((299 * px[0] + 587 * px[1] + 114 * px[2] + 500) / 1000);
    }
    bytes = std::string_view(reinterpret_cast<const char*>(gray.data()), gray.size());
  }
  if (bytes.size() >= transport::kShmBlobThreshold) {
    c.set_image_blob(transport::current_blob_writer().add(out, bytes) + 1);
  } else {
    c.set_image_data(bytes.data(), bytes.size());
  }
  out->mutable_id()->set_type("convoy.data.Camera");
  out->mutable_proto()->set_type_name("convoy.data.Camera");
  c.SerializeToString(out->mutable_proto()->mutable_data());
}

void CameraSensors::depth_datapack(size_t i, engine::DataPack* out) {
  Camera& cam = cameras_[i];
  cam.want_depth = true;
  if (!cam.rendered)
    first_render(cam);
  else if (!cam.has_depth)
    render(cam);  // (noise redrawn: a new sample of the same view)
  nlohmann::json j;
  j["width"] = cam.frame.width;
  j["height"] = cam.frame.height;
  numpy_blob(&j, "depth", cam.frame.depth, cam.frame.height, cam.frame.width, out);
  out->mutable_id()->set_type("json");
  std::vector<uint8_t> bytes = nlohmann::json::to_msgpack(j);
  out->set_json_msgpack(std::string(bytes.begin(), bytes.end()));
}

void CameraSensors::boxes_datapack(size_t i, engine::DataPack* out) {
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
                     {"pixels", b.pixel_count}});
  }
  nlohmann::json j = {{"width", cam.frame.width}, {"height", cam.frame.height}, {"boxes", boxes}};
  out->mutable_id()->set_type("json");
  std::vector<uint8_t> bytes = nlohmann::json::to_msgpack(j);
  out->set_json_msgpack(std::string(bytes.begin(), bytes.end()));
}

}  // namespace convoy::world
