// Renderer's internals, shared by its source files (renderer.cpp: frames and draws;
// renderer_shadows.cpp: the sun's shadow map; renderer_sky.cpp: sky and precipitation).
// Not part of the render library's interface.
#pragma once

#include <GLES3/gl3.h>

#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <map>
#include <vector>

#include "render/egl_context.h"
#include "render/gl_program.h"
#include "render/gpu_resources.h"
#include "render/precipitation.h"
#include "render/renderer.h"

namespace convoy::render {
namespace renderer_detail {

// Triangles submitted between two glFlush calls (see Impl::draw).
constexpr size_t kFlushEveryTriangles = 16384;

// Bits of Draw::variant: which program draws it.
constexpr unsigned kTextured = 1, kPerVertex = 2, kSpecular = 4, kShadowed = 8;

// Where this frame's shadow map lies: a square of 2 x half_size around `centre` in the light's
// view (x, y), `depth` either side of it along the light (z).
struct ShadowRegion {
  bool valid = false;
  glm::dmat4 light_view{1.0};
  glm::dvec3 centre{0.0};
  double half_size = 0, depth = 0;
  // Whether a sphere (world centre, radius) can take a shadow from the map: any of it inside.
  bool reaches(const glm::dvec3& world_centre, double r) const {
    const glm::dvec3 lc(light_view * glm::dvec4(world_centre, 1));
    return valid && std::abs(lc.x - centre.x) <= half_size + r &&
           std::abs(lc.y - centre.y) <= half_size + r && std::abs(lc.z - centre.z) <= depth + r;
  }
};

struct Draw {
  // Order: things around the camera (ground, walls) after the rest, so that what stands in
  // front of them hides their pixels before they are shaded; then by program; then front to
  // back by bounding sphere's centre.
  bool surrounds_camera;
  unsigned variant;
  double distance;
  int instance;
  int mesh;  // the instance's mesh, or a coarser level of it
  glm::mat4 model_view;
  glm::mat3 normal_matrix;
};

}  // namespace renderer_detail

struct Renderer::Impl {
  EglContext context;  // first: made first, destroyed last
  GpuSceneCache scenes;
  RenderTargetCache targets;
  std::map<ProgramKey, SurfaceProgram> programs;  // built when first needed
  PrecipitationProgram precipitation;             // built when first needed
  SkyProgram sky;                                 // built when first needed
  std::vector<PrecipitationVertex> precipitation_vertices;
  // Sun shadows (Scene::shadows): the depth program, the map and its framebuffer, and this
  // frame's eye-to-map matrix and biases.
  ShadowProgram shadow_program;
  GLuint shadow_fbo = 0, shadow_texture = 0;
  int shadow_size = 0;
  glm::mat4 shadow_matrix{1.0f};
  glm::vec2 shadow_bias{0.0f};
  renderer_detail::ShadowRegion shadow_region;
  uint64_t frame_number = 0;
  std::map<GLuint, uint64_t> program_frame;  // frame whose uniforms a program holds
  GLint max_size = 0;
  double per_vertex_below = Renderer::kPerVertexLightingBelow;
  double lod_pixel_error = Renderer::kLodPixelError;
  RenderStats stats;
  // Reused from frame to frame.
  std::vector<renderer_detail::Draw> draws;
  std::vector<uint8_t> rgba;
  std::vector<uint32_t> ids;  // bytes r, g, b, a of the id attachment: the id, little-endian
  std::vector<float> distance_rgba;
  std::vector<float> instance_distance;  // by instance: metres to its bounds' centre (drawn ones)

  ~Impl() {
    try {
      context.make_current();
    } catch (...) {
      return;  // another thread holds the context: leak the GL objects rather than crash
    }
    for (auto& [key, p] : programs) destroy_program(&p);
    if (shadow_program.id) glDeleteProgram(shadow_program.id);
    if (shadow_fbo) glDeleteFramebuffers(1, &shadow_fbo);
    if (shadow_texture) glDeleteTextures(1, &shadow_texture);
    if (sky.id) {
      glDeleteProgram(sky.id);
      glDeleteVertexArrays(1, &sky.vao);
    }
    if (precipitation.id) {
      glDeleteProgram(precipitation.id);
      glDeleteVertexArrays(1, &precipitation.vao);
      glDeleteBuffers(1, &precipitation.vbo);
    }
  }
  void draw_precipitation(const Atmosphere& a, int width, int height);
  // The sky gradient where nothing was drawn (colour only).
  void draw_sky(const Sky& sky, const Pose& camera_world_pose, const CameraSpec& spec);
  // Renders light `li`'s shadow map around the camera of `view` (world to eye) with the
  // casters whose shadow can fall into the camera's view; false when the light is too low to
  // cast shadows.
  bool render_shadow_map(const Scene& scene, int li, const glm::dmat4& view, const CameraSpec& spec,
                         const GpuScene& gpu);

  const SurfaceProgram& program(const ProgramKey& key) {
    auto it = programs.find(key);
    if (it == programs.end()) it = programs.emplace(key, build_surface_program(key)).first;
    return it->second;
  }

  void upload_frame_uniforms(const SurfaceProgram& p, const Scene& scene, const glm::dmat4& view,
                             const CameraSpec& spec);
  void collect_draws(const Scene& scene, const glm::dmat4& view, const CameraSpec& spec);
  void draw(ProgramKey key, const Scene& scene, const glm::dmat4& view, const CameraSpec& spec,
            const GpuScene& gpu);
};

}  // namespace convoy::render
