#include "render/scene.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>

#include "render/box_level.h"
#include "render/image_io.h"

namespace convoy::render {
namespace {

uint64_t next_uid() {
  static std::atomic<uint64_t> counter{1};
  return counter.fetch_add(1);
}

std::string index_message(const char* what, int index, size_t size) {
  return std::string(what) + ": index " + std::to_string(index) + " out of range (" +
         std::to_string(size) + ")";
}

// The smallest sphere about the centre of the axis-aligned bounding box that holds every vertex.
Scene::Bounds bounds_of(const MeshData& mesh) {
  if (mesh.positions.empty()) return {{0, 0, 0}, 0};
  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = mesh.positions[k];
  for (size_t i = 0; i < mesh.positions.size(); i += 3) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], mesh.positions[i + k]);
      hi[k] = std::max(hi[k], mesh.positions[i + k]);
    }
  }
  Scene::Bounds b{{(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2}, 0};
  b.lo = {lo[0], lo[1], lo[2]};
  b.hi = {hi[0], hi[1], hi[2]};
  double r2 = 0;
  for (size_t i = 0; i < mesh.positions.size(); i += 3) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double d = mesh.positions[i + k] - b.centre[k];
      d2 += d * d;
    }
    r2 = std::max(r2, d2);
  }
  b.radius = static_cast<float>(std::sqrt(r2)) * 1.0001f;  // float rounding
  return b;
}

}  // namespace

Scene::Scene() : uid_(next_uid()) {}

Scene::Scene(Scene&& other) noexcept { *this = std::move(other); }

Scene& Scene::operator=(Scene&& other) noexcept {
  if (this == &other) return *this;
  uid_ = other.uid_;
  meshes_ = std::move(other.meshes_);
  bounds_ = std::move(other.bounds_);
  lods_ = std::move(other.lods_);
  textures_ = std::move(other.textures_);
  instances_ = std::move(other.instances_);
  lights_ = std::move(other.lights_);
  ambient_ = other.ambient_;
  background_ = other.background_;
  atmosphere_ = other.atmosphere_;
  shadows_ = other.shadows_;
  sky_ = other.sky_;
  // The renderer caches GPU copies by uid: the emptied source must not share it.
  other.uid_ = next_uid();
  other.meshes_.clear();
  other.bounds_.clear();
  other.lods_.clear();
  other.textures_.clear();
  other.instances_.clear();
  other.lights_.clear();
  return *this;
}

int Scene::add_mesh(const MeshData& mesh) {
  const std::string what = "Scene::add_mesh (mesh " + std::to_string(meshes_.size()) + ")";
  validate_mesh(mesh, what.c_str());
  meshes_.push_back(mesh);
  if (meshes_.back().normals.empty()) compute_normals(&meshes_.back());
  bounds_.push_back(bounds_of(mesh));
  lods_.emplace_back();
  return static_cast<int>(meshes_.size() - 1);
}

int Scene::add_mesh_levels(const MeshLevels& levels) {
  if (levels.meshes.empty() || levels.meshes.size() != levels.errors.size()) {
    throw std::invalid_argument("Scene::add_mesh_levels: need one error per mesh, and a mesh");
  }
  const int finest = add_mesh(levels.meshes[0]);
  for (size_t i = 1; i < levels.meshes.size(); ++i) {
    const int coarser = add_mesh(levels.meshes[i]);
    lods_[finest].push_back(Lod{coarser, levels.errors[i]});
  }
  // The box last, when it has at most 60 % of the coarsest level's triangles (see box_level.h).
  if (levels.box && levels.meshes.back().triangle_count() * 3 >= 5 * 12) {
    if (auto box = box_level(levels.meshes[0])) {
      const float error = std::max(box->error, levels.errors.back());
      const int coarsest = add_mesh(box->mesh);
      lods_[finest].push_back(Lod{coarsest, error});
    }
  }
  return finest;
}

int Scene::add_texture(const uint8_t* rgba, int width, int height) {
  if (width <= 0 || height <= 0 || !rgba) {
    throw std::invalid_argument("Scene::add_texture: bad image " + std::to_string(width) + "x" +
                                std::to_string(height));
  }
  Texture t{width, height, {}};
  t.rgba.assign(rgba, rgba + static_cast<size_t>(width) * height * 4);
  textures_.push_back(std::move(t));
  return static_cast<int>(textures_.size() - 1);
}

int Scene::add_texture_file(const std::string& path) {
  const Image image = load_image_rgba(path);
  return add_texture(image.data.data(), image.width, image.height);
}

void Scene::check_material(const Material& material) const {
  if (material.texture < -1 || material.texture >= static_cast<int>(textures_.size())) {
    throw std::out_of_range(index_message("Material::texture", material.texture, textures_.size()));
  }
}

int Scene::add_instance(int mesh, const Material& material, const Pose& world_from_object,
                        uint32_t model_id, uint32_t class_id) {
  if (mesh < 0 || mesh >= static_cast<int>(meshes_.size())) {
    throw std::out_of_range(index_message("Scene::add_instance: mesh", mesh, meshes_.size()));
  }
  check_material(material);
  instances_.push_back(Instance{mesh, material, world_from_object, model_id, class_id, true});
  return static_cast<int>(instances_.size() - 1);
}

Scene::Instance& Scene::instance_at(int index, const char* what) {
  if (index < 0 || index >= static_cast<int>(instances_.size())) {
    throw std::out_of_range(index_message(what, index, instances_.size()));
  }
  return instances_[index];
}

void Scene::set_pose(int instance, const Pose& world_from_object) {
  instance_at(instance, "Scene::set_pose").world_from_object = world_from_object;
}

void Scene::set_casts_shadows(int instance, bool casts) {
  instance_at(instance, "Scene::set_casts_shadows").casts_shadows = casts;
}

void Scene::set_visible(int instance, bool visible) {
  instance_at(instance, "Scene::set_visible").visible = visible;
}

void Scene::set_material(int instance, const Material& material) {
  Instance& i = instance_at(instance, "Scene::set_material");
  check_material(material);
  i.material = material;
}

void Scene::add_light(const Light& light) {
  if (lights_.size() >= kMaxLights) {
    throw std::length_error("Scene::add_light: at most " + std::to_string(kMaxLights) +
                            " lights are supported");
  }
  lights_.push_back(light);
}

}  // namespace convoy::render
