// What a camera sees: meshes, textures, materials, lights and posed instances.
//
// A Scene is the renderer's input. Meshes and textures are added once and never change (the
// Renderer uploads each to the GPU the first time it renders the Scene); instance poses,
// visibility and materials may change every step. Defaults are SDF 1.6's (<scene>, <light>,
// <material> specular), except that a Material is mid grey, as Gazebo draws a visual without
// one. Colours are linear RGBA in [0, 1].
//
//   Scene scene;
//   int box = scene.add_mesh(make_box(1, 1, 1));
//   Material red;  red.diffuse = {1, 0, 0, 1};
//   int car = scene.add_instance(box, red, make_pose(5, 0, 0.5), /*model_id=*/7, /*class=*/1);
//   scene.add_light(Light{});           // the default: white sunlight from straight above
//   ...  scene.set_pose(car, make_pose(6, 0, 0.5));
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "render/mesh.h"
#include "render/pose.h"

namespace convoy::render {

using Rgba = std::array<float, 4>;

// Fixed-function (Blinn-Phong) surface, as SDF <material> / OGRE describe it.
struct Material {
  Rgba diffuse{0.7f, 0.7f, 0.7f, 1.0f};
  Rgba ambient{0.7f, 0.7f, 0.7f, 1.0f};   // multiplied by the scene's ambient light
  Rgba specular{0.0f, 0.0f, 0.0f, 1.0f};  // SDF's default: no highlights
  Rgba emissive{0.0f, 0.0f, 0.0f, 0.0f};  // added as is
  bool textured_emissive = false;         // the texture multiplies emissive too (a lit picture)
  float shininess = 32.0f;                // Blinn-Phong exponent
  int texture = -1;           // Scene::add_texture index; it multiplies diffuse and ambient
  bool double_sided = false;  // draw back faces too (lit with the flipped normal)

  bool operator==(const Material&) const = default;
};

// SDF <light>. Directions point where the light shines; positions and directions are in the
// world frame. Attenuation 1 / (constant + linear d + quadratic d^2), zero beyond `range`;
// directional lights are not attenuated.
struct Light {
  enum Type { kDirectional, kPoint, kSpot };
  Type type = kDirectional;
  std::array<float, 3> position{0, 0, 10};
  std::array<float, 3> direction{0, 0, -1};
  Rgba diffuse{1, 1, 1, 1};
  Rgba specular{0.1f, 0.1f, 0.1f, 1};
  float range = 10.0f;
  float attenuation_constant = 1.0f;
  float attenuation_linear = 1.0f;
  float attenuation_quadratic = 0.0f;
  // Spot cone, full angles in radians: full intensity inside inner_angle, fading
  // ((cos a - cos outer/2) / (cos inner/2 - cos outer/2))^falloff to zero at outer_angle.
  float spot_inner_angle = 0.0f;
  float spot_outer_angle = 1.0f;
  float spot_falloff = 1.0f;
  bool cast_shadows = false;  // accepted and ignored: the renderer draws no shadows
};

// The weather as a camera sees it (the world engine sets it from the weather datapack).
// Fog: a surface at distance d keeps exp(-3.912 d / visibility) of its own light and takes the
// rest from fog_color (Koschmieder: a black object's contrast against the fog is 2 % at the
// visibility distance); the background is not fogged (set it to the fog's colour in fog).
// Wetness and snow cover act on up-facing surfaces lit per pixel: wet ones darken and mirror
// `sky` at grazing angles, snowy ones turn white. Precipitation draws rain streaks or snow
// flakes over the image, slanted by `fall_slant` (image x per image y), a new pattern for each
// (seed, time): the same seed and time give the same frame.
struct Atmosphere {
  float visibility = std::numeric_limits<float>::infinity();  // m
  Rgba fog_color{0.78f, 0.8f, 0.82f, 1.0f};
  float wetness = 0;     // 0-1
  float snow_cover = 0;  // 0-1
  Rgba sky{0.55f, 0.7f, 0.9f, 1.0f};
  float precipitation = 0;  // 0-1
  bool snow = false;        // flakes instead of streaks
  float fall_slant = 0;
  uint32_t seed = 0;
  double time = 0;  // s

  bool fog() const { return std::isfinite(visibility); }
  bool surface_weather() const { return wetness > 0 || snow_cover > 0; }
  bool operator==(const Atmosphere&) const = default;
};

// The sky behind the scene. With `gradient`, a view ray at elevation e (0 at and below the
// horizon, 1 straight up) sees horizon + (zenith - horizon) sqrt(e); without, the background
// colour everywhere (the default). from_background() makes a daylight sky around a colour:
// the horizon paler (half-way to a grey as bright as its brightest channel), the zenith 30 %
// deeper, both by `strength` (0: uniform).
struct Sky {
  bool gradient = false;
  Rgba horizon{0.7f, 0.7f, 0.7f, 1.0f};
  Rgba zenith{0.7f, 0.7f, 0.7f, 1.0f};
  bool operator==(const Sky&) const = default;
  static Sky from_background(const Rgba& c, float strength = 1.0f) {
    const float grey = std::max({c[0], c[1], c[2]});
    Sky s;
    s.gradient = true;
    for (int k = 0; k < 3; ++k) {
      s.horizon[k] = c[k] + (grey - c[k]) * 0.5f * strength;
      s.zenith[k] = c[k] * (1.0f - 0.3f * strength);
    }
    s.horizon[3] = s.zenith[3] = 1.0f;
    return s;
  }
};

// Sun shadows: the first directional light, while it is at least 3 degrees above the horizon,
// casts shadows through a shadow map of map_size x map_size texels covering the ground from
// the camera to `distance` metres ahead of it (beyond, no shadows). Off by default.
struct Shadows {
  bool enabled = false;
  double distance = 60;  // m
  int map_size = 1024;
  bool operator==(const Shadows&) const = default;
};

class Scene {
 public:
  // The renderer draws at most this many lights; add_light throws beyond it.
  static constexpr int kMaxLights = 16;

  struct Instance {
    int mesh;
    Material material;
    Pose world_from_object;
    uint32_t model_id;  // ground-truth label; 0 = unlabelled (never gets a bounding box)
    uint32_t class_id;
    bool visible = true;
    bool casts_shadows = true;  // drawn into the sun's shadow map
  };
  struct Texture {
    int width, height;
    std::vector<uint8_t> rgba;  // row 0 = top of the image
  };
  // A mesh's bounding sphere in its own frame (used to skip what the camera cannot see).
  struct Bounds {
    std::array<float, 3> centre;
    float radius;
    std::array<float, 3> lo{}, hi{};  // the axis-aligned bounding box
  };
  // A coarser stand-in for a mesh and its geometric error (metres, in the mesh's frame).
  struct Lod {
    int mesh;
    float error;
  };

  Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;
  // A moved-from Scene is empty and gets a new uid.
  Scene(Scene&& other) noexcept;
  Scene& operator=(Scene&& other) noexcept;

  // Returns the mesh's index. Computes normals if it has none; throws std::invalid_argument if
  // the arrays are inconsistent.
  int add_mesh(const MeshData& mesh);
  // Adds every level of `levels` and returns the finest's index, to use as any mesh's. Where
  // an instance of it is small on screen, the renderer draws the coarsest level whose error
  // covers at most Renderer::kLodPixelError pixels there. The mesh's bounding box is added as
  // its coarsest level (box_level.h) when it pays.
  int add_mesh_levels(const MeshLevels& levels);
  // Copies a w x h RGBA8 image (row 0 = top) and returns its index.
  int add_texture(const uint8_t* rgba, int width, int height);
  // Loads a PNG or JPEG file (see image_io.h); throws std::runtime_error naming the file.
  int add_texture_file(const std::string& path);

  // Returns the instance's index. Throws std::out_of_range for an unknown mesh or texture.
  int add_instance(int mesh, const Material& material, const Pose& world_from_object,
                   uint32_t model_id = 0, uint32_t class_id = 0);
  void set_pose(int instance, const Pose& world_from_object);
  void set_visible(int instance, bool visible);
  // Whether an instance casts shadows (SDF <cast_shadows>; flat ground need not).
  void set_casts_shadows(int instance, bool casts);
  void set_material(int instance, const Material& material);

  void add_light(const Light& light);
  void clear_lights() { lights_.clear(); }
  void set_ambient(const Rgba& rgba) { ambient_ = rgba; }
  void set_background(const Rgba& rgba) { background_ = rgba; }
  void set_atmosphere(const Atmosphere& a) { atmosphere_ = a; }
  void set_shadows(const Shadows& s) { shadows_ = s; }
  void set_sky(const Sky& s) { sky_ = s; }

  // Read access for the renderer.
  uint64_t uid() const { return uid_; }  // unique per Scene object in this process
  const std::vector<MeshData>& meshes() const { return meshes_; }
  const std::vector<Bounds>& mesh_bounds() const { return bounds_; }
  // By mesh: its coarser levels, finest first (empty for most meshes).
  const std::vector<std::vector<Lod>>& mesh_lods() const { return lods_; }
  const std::vector<Texture>& textures() const { return textures_; }
  const std::vector<Instance>& instances() const { return instances_; }
  const std::vector<Light>& lights() const { return lights_; }
  const Rgba& ambient() const { return ambient_; }
  const Rgba& background() const { return background_; }
  const Atmosphere& atmosphere() const { return atmosphere_; }
  const Shadows& shadows() const { return shadows_; }
  const Sky& sky() const { return sky_; }

 private:
  Instance& instance_at(int index, const char* what);
  void check_material(const Material& material) const;

  uint64_t uid_;
  std::vector<MeshData> meshes_;
  std::vector<Bounds> bounds_;
  std::vector<std::vector<Lod>> lods_;
  std::vector<Texture> textures_;
  std::vector<Instance> instances_;
  std::vector<Light> lights_;
  Rgba ambient_{0.4f, 0.4f, 0.4f, 1.0f};     // SDF <scene><ambient> default
  Rgba background_{0.7f, 0.7f, 0.7f, 1.0f};  // SDF <scene><background> default
  Atmosphere atmosphere_;                    // none: clear air
  Shadows shadows_;
  Sky sky_;  // the background colour
};

}  // namespace convoy::render
