#include "render/renderer.h"

#include <GLES3/gl3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>

#include "core/memory.h"
#include "render/egl_context.h"
#include "render/frustum.h"
#include "render/gl_program.h"
#include "render/gpu_resources.h"
#include "render/precipitation.h"
#include "render/readback.h"

namespace convoy::render {
namespace {

// The GL camera (x right, y up, looking down -z) in the SDF camera's frame (x forward, y left,
// z up): its columns are GL's axes.
const glm::dmat4 kSdfFromGlCamera(glm::dvec4(0, -1, 0, 0), glm::dvec4(0, 0, 1, 0),
                                  glm::dvec4(-1, 0, 0, 0), glm::dvec4(0, 0, 0, 1));

// Perspective projection for the pinhole of CameraSpec, flipped vertically so that the first
// row glReadPixels returns is the top of the image (the winding flips too: see glFrontFace).
glm::dmat4 projection(const CameraSpec& spec) {
  const double t = std::tan(spec.hfov / 2), aspect = double(spec.width) / spec.height;
  const double n = spec.near_clip, f = spec.far_clip;
  glm::dmat4 p(0.0);
  p[0][0] = 1 / t;
  p[1][1] = -aspect / t;
  p[2][2] = (f + n) / (n - f);
  p[2][3] = -1;
  p[3][2] = 2 * f * n / (n - f);
  return p;
}

void check_spec(const CameraSpec& s) {
  auto fail = [](const std::string& why) {
    throw std::invalid_argument("Renderer::render: CameraSpec " + why);
  };
  if (s.width <= 0 || s.height <= 0) {
    fail("size must be positive, got " + std::to_string(s.width) + "x" + std::to_string(s.height));
  }
  if (!(s.hfov > 0 && s.hfov < std::numbers::pi))
    fail("hfov must be in (0, pi), got " + std::to_string(s.hfov));
  if (!(s.near_clip > 0 && s.far_clip > s.near_clip && std::isfinite(s.far_clip))) {
    fail("clip must satisfy 0 < near < far, got near " + std::to_string(s.near_clip) + ", far " +
         std::to_string(s.far_clip));
  }
}

// Each box's full extent: the projection of its model's visible instances' bounding boxes
// (BoundingBox::full_*).
void full_extents(const Scene& scene, const glm::dmat4& view, const CameraSpec& spec,
                  std::vector<BoundingBox>* boxes) {
  if (boxes->empty()) return;
  const double fx = spec.width / 2.0 / std::tan(spec.hfov / 2);
  for (auto& b : *boxes) {
    b.full_x_min = b.full_y_min = std::numeric_limits<float>::infinity();
    b.full_x_max = b.full_y_max = -std::numeric_limits<float>::infinity();
  }
  const auto& instances = scene.instances();
  for (const Scene::Instance& inst : instances) {
    if (inst.model_id == 0 || !inst.visible) continue;
    auto it = std::lower_bound(boxes->begin(), boxes->end(), inst.model_id,
                               [](const BoundingBox& b, uint32_t id) { return b.model_id < id; });
    if (it == boxes->end() || it->model_id != inst.model_id) continue;
    const Scene::Bounds& bd = scene.mesh_bounds()[inst.mesh];
    const glm::dmat4 mv = view * glm::make_mat4(inst.world_from_object.data());
    for (int c = 0; c < 8; ++c) {
      const glm::dvec4 corner((c & 1) ? bd.hi[0] : bd.lo[0], (c & 2) ? bd.hi[1] : bd.lo[1],
                              (c & 4) ? bd.hi[2] : bd.lo[2], 1.0);
      const glm::dvec3 e = mv * corner;
      if (-e.z < spec.near_clip) {  // behind the camera: unbounded
        it->full_x_min = it->full_y_min = -1e6f;
        it->full_x_max = it->full_y_max = 1e6f;
        continue;
      }
      const double u = spec.width / 2.0 + fx * e.x / -e.z;
      const double v = spec.height / 2.0 - fx * e.y / -e.z;
      it->full_x_min = std::min(it->full_x_min, static_cast<float>(u));
      it->full_x_max = std::max(it->full_x_max, static_cast<float>(u));
      it->full_y_min = std::min(it->full_y_min, static_cast<float>(v));
      it->full_y_max = std::max(it->full_y_max, static_cast<float>(v));
    }
  }
}

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

}  // namespace

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
  ShadowRegion shadow_region;
  uint64_t frame_number = 0;
  std::map<GLuint, uint64_t> program_frame;  // frame whose uniforms a program holds
  GLint max_size = 0;
  double per_vertex_below = Renderer::kPerVertexLightingBelow;
  double lod_pixel_error = Renderer::kLodPixelError;
  RenderStats stats;
  // Reused from frame to frame.
  std::vector<Draw> draws;
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

void Renderer::Impl::upload_frame_uniforms(const SurfaceProgram& p, const Scene& scene,
                                           const glm::dmat4& view, const CameraSpec& spec) {
  glUniformMatrix4fv(p.projection, 1, GL_FALSE, glm::value_ptr(glm::mat4(projection(spec))));
  glUniform3fv(p.scene_ambient, 1, scene.ambient().data());
  const Atmosphere& a = scene.atmosphere();
  if (p.fog_k >= 0) {
    glUniform1f(p.fog_k, static_cast<float>(3.912 / a.visibility));
    glUniform3fv(p.fog_color, 1, a.fog_color.data());
  }
  if (p.up >= 0) {
    const glm::vec3 up(glm::normalize(glm::dmat3(view) * glm::dvec3(0, 0, 1)));
    glUniform3fv(p.up, 1, glm::value_ptr(up));
    glUniform1f(p.wetness, a.wetness);
    glUniform1f(p.snow, a.snow_cover);
    glUniform3fv(p.sky, 1, a.sky.data());
  }
  if (p.shadow_matrix >= 0) {
    glUniformMatrix4fv(p.shadow_matrix, 1, GL_FALSE, glm::value_ptr(shadow_matrix));
    glUniform2fv(p.shadow_bias, 1, glm::value_ptr(shadow_bias));
  }
  const auto& lights = scene.lights();
  const int n = static_cast<int>(lights.size());
  std::vector<glm::vec4> direction(n);
  std::vector<glm::vec3> position(n), diffuse(n), specular(n), attenuation(n), spot(n);
  for (int i = 0; i < n; ++i) {
    const Light& l = lights[i];
    const glm::dvec3 pos = view * glm::dvec4(l.position[0], l.position[1], l.position[2], 1);
    glm::dvec3 dir = glm::dmat3(view) * glm::dvec3(l.direction[0], l.direction[1], l.direction[2]);
    dir = glm::length(dir) > 0 ? glm::normalize(dir) : glm::dvec3(0, 0, -1);
    position[i] = glm::vec3(pos);
    direction[i] = glm::vec4(glm::vec3(dir), l.range);
    diffuse[i] = glm::vec3(l.diffuse[0], l.diffuse[1], l.diffuse[2]);
    specular[i] = glm::vec3(l.specular[0], l.specular[1], l.specular[2]);
    attenuation[i] =
        glm::vec3(l.attenuation_constant, l.attenuation_linear, l.attenuation_quadratic);
    const double cos_outer = std::cos(l.spot_outer_angle / 2.0);
    const double cos_inner = std::cos(std::min(l.spot_inner_angle, l.spot_outer_angle) / 2.0);
    spot[i] = glm::vec3(cos_outer, 1.0 / std::max(cos_inner - cos_outer, 1e-6),
                        std::max(l.spot_falloff, 0.0f));
  }
  if (n > 0) {
    glUniform3fv(p.light_position, n, glm::value_ptr(position[0]));
    glUniform4fv(p.light_direction, n, glm::value_ptr(direction[0]));
    glUniform3fv(p.light_diffuse, n, glm::value_ptr(diffuse[0]));
    glUniform3fv(p.light_specular, n, glm::value_ptr(specular[0]));
    glUniform3fv(p.light_attenuation, n, glm::value_ptr(attenuation[0]));
    glUniform3fv(p.light_spot, n, glm::value_ptr(spot[0]));
  }
}

// Keeps the visible instances whose bounding sphere meets the view frustum, nearest first.
void Renderer::Impl::collect_draws(const Scene& scene, const glm::dmat4& view,
                                   const CameraSpec& spec) {
  const double focal_px = spec.width / 2.0 / std::tan(spec.hfov / 2);
  bool lights_have_specular = false;
  for (const Light& l : scene.lights()) {
    lights_have_specular |= l.specular[0] > 0 || l.specular[1] > 0 || l.specular[2] > 0;
  }
  const ViewFrustum frustum(spec);
  draws.clear();
  const auto& instances = scene.instances();
  instance_distance.assign(instances.size(), std::numeric_limits<float>::infinity());
  for (int i = 0; i < static_cast<int>(instances.size()); ++i) {
    const Scene::Instance& inst = instances[i];
    if (!inst.visible) continue;
    const Scene::Bounds& b = scene.mesh_bounds()[inst.mesh];
    const glm::dmat4 mv = view * glm::make_mat4(inst.world_from_object.data());
    const glm::dvec3 c = mv * glm::dvec4(b.centre[0], b.centre[1], b.centre[2], 1);
    const double scale = std::max({glm::length(glm::dvec3(mv[0])), glm::length(glm::dvec3(mv[1])),
                                   glm::length(glm::dvec3(mv[2]))});
    const double r = b.radius * scale;
    instance_distance[i] = static_cast<float>(glm::length(c));
    if (frustum.misses_sphere(c, r)) continue;
    const glm::dmat3 normal = glm::transpose(glm::inverse(glm::dmat3(mv)));
    // Level of detail: the coarsest whose error, seen at the instance's nearest point, stays
    // within lod_pixel_error pixels.
    int mesh = inst.mesh;
    const double px_per_metre_near = scale * focal_px / std::max(-c.z - r, spec.near_clip);
    for (const Scene::Lod& lod : scene.mesh_lods()[inst.mesh]) {
      if (lod.error * px_per_metre_near > lod_pixel_error) break;
      mesh = lod.mesh;
    }
    // Light per vertex where triangles are small on screen (see gl_program.h).
    const double radius_px = r * focal_px / std::max(-c.z, 1e-9);
    const double px_per_triangle =
        std::numbers::pi * radius_px * radius_px / (0.5 * scene.meshes()[mesh].triangle_count());
    const bool per_vertex =
        -c.z > r && !inst.material.double_sided && px_per_triangle < per_vertex_below;
    const auto& ks = inst.material.specular;
    const bool specular = lights_have_specular && (ks[0] > 0 || ks[1] > 0 || ks[2] > 0);
    // Shadows are looked up only where the map reaches (outside it, all is lit anyway).
    const glm::dvec3 world_centre(glm::make_mat4(inst.world_from_object.data()) *
                                  glm::dvec4(b.centre[0], b.centre[1], b.centre[2], 1));
    const bool shadowed = shadow_region.reaches(world_centre, r + shadow_bias.x);
    const unsigned variant = (inst.material.texture >= 0 ? kTextured : 0) |
                             (per_vertex ? kPerVertex : 0) | (specular ? kSpecular : 0) |
                             (shadowed ? kShadowed : 0);
    draws.push_back(
        Draw{glm::length(c) < r, variant, -c.z, i, mesh, glm::mat4(mv), glm::mat3(normal)});
  }
  std::sort(draws.begin(), draws.end(), [](const Draw& a, const Draw& b) {
    if (a.surrounds_camera != b.surrounds_camera) return b.surrounds_camera;
    if (a.variant != b.variant) return a.variant < b.variant;
    return a.distance != b.distance ? a.distance < b.distance : a.instance < b.instance;
  });
}

void Renderer::Impl::draw(ProgramKey key, const Scene& scene, const glm::dmat4& view,
                          const CameraSpec& spec, const GpuScene& gpu) {
  stats = RenderStats{};
  stats.instances_drawn = static_cast<int>(draws.size());
  ++frame_number;
  const SurfaceProgram* program = nullptr;
  const int shadow_light = key.shadow_light;
  unsigned variant = 0;
  int bound_mesh = -1;
  GLuint bound_texture = 0;
  bool culling = true;
  const Material* last = nullptr;
  size_t triangles_queued = 0;
  for (const Draw& d : draws) {
    const Scene::Instance& inst = scene.instances()[d.instance];
    if (!program || d.variant != variant) {
      variant = d.variant;
      key.textured = variant & kTextured;
      key.per_vertex = variant & kPerVertex;
      key.specular = variant & kSpecular;
      key.shadow_light = variant & kShadowed ? shadow_light : -1;
      program = &this->program(key);
      glUseProgram(program->id);
      if (program_frame[program->id] != frame_number) {
        upload_frame_uniforms(*program, scene, view, spec);
        program_frame[program->id] = frame_number;
      }
      last = nullptr;
    }
    const SurfaceProgram& p = *program;
    const GpuMesh& mesh = gpu.meshes[d.mesh];
    if (d.mesh != bound_mesh) {
      glBindVertexArray(mesh.vao);
      bound_mesh = d.mesh;
    }
    stats.coarser_level += d.mesh != inst.mesh;
    glUniformMatrix4fv(p.model_view, 1, GL_FALSE, glm::value_ptr(d.model_view));
    glUniformMatrix3fv(p.normal_matrix, 1, GL_FALSE, glm::value_ptr(d.normal_matrix));
    const Material& m = inst.material;
    if (!last || !(*last == m)) {
      glUniform4fv(p.diffuse, 1, m.diffuse.data());
      glUniform4fv(p.ambient, 1, m.ambient.data());
      glUniform4fv(p.specular, 1, m.specular.data());
      glUniform4fv(p.emissive, 1, m.emissive.data());
      if (p.textured_emissive >= 0) glUniform1f(p.textured_emissive, m.textured_emissive);
      glUniform1f(p.shininess, std::max(m.shininess, 1e-3f));
      glUniform1i(p.double_sided, m.double_sided);
      last = &m;
    }
    if (m.texture >= 0 && gpu.textures[m.texture] != bound_texture) {
      bound_texture = gpu.textures[m.texture];
      glBindTexture(GL_TEXTURE_2D, bound_texture);
    }
    if (m.double_sided == culling) {
      culling = !m.double_sided;
      culling ? glEnable(GL_CULL_FACE) : glDisable(GL_CULL_FACE);
    }
    if (p.instance_id >= 0) {
      const uint32_t id = static_cast<uint32_t>(d.instance) + 1;
      glUniform4f(p.instance_id, (id & 0xff) / 255.0f, ((id >> 8) & 0xff) / 255.0f,
                  ((id >> 16) & 0xff) / 255.0f, ((id >> 24) & 0xff) / 255.0f);
    }
    glDrawElements(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr);
    stats.triangles_drawn += mesh.index_count / 3;
    // Hand what is queued to the rasteriser threads every so often: llvmpipe rasterises a
    // batch while this thread prepares the next, instead of waiting for the whole frame.
    triangles_queued += mesh.index_count / 3;
    if (triangles_queued >= kFlushEveryTriangles) {
      glFlush();
      triangles_queued = 0;
    }
    stats.per_vertex_lit += (d.variant & kPerVertex) != 0;
  }
  glBindVertexArray(0);
  if (!culling) glEnable(GL_CULL_FACE);
}

bool Renderer::Impl::render_shadow_map(const Scene& scene, int li, const glm::dmat4& view,
                                       const CameraSpec& spec, const GpuScene& gpu) {
  const Light& sun = scene.lights()[li];
  glm::dvec3 d(sun.direction[0], sun.direction[1], sun.direction[2]);
  if (!(glm::length(d) > 0)) return false;
  d = glm::normalize(d);
  if (-d.z < std::sin(3.0 * std::numbers::pi / 180)) return false;  // the sun below 3 degrees
  const Shadows& cfg = scene.shadows();
  const int size = std::clamp(cfg.map_size, 64, max_size);
  if (!shadow_program.id) shadow_program = build_shadow_program();
  if (size != shadow_size) {
    if (shadow_fbo) glDeleteFramebuffers(1, &shadow_fbo);
    if (shadow_texture) glDeleteTextures(1, &shadow_texture);
    glGenTextures(1, &shadow_texture);
    glBindTexture(GL_TEXTURE_2D, shadow_texture);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_DEPTH_COMPONENT24, size, size);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenFramebuffers(1, &shadow_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadow_texture, 0);
    const GLenum none = GL_NONE;
    glDrawBuffers(1, &none);
    glReadBuffer(GL_NONE);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("render: the shadow map's framebuffer is incomplete");
    shadow_size = size;
  }
  // The map covers a square around the ground ahead of the camera, seen along the light; its
  // centre snaps to whole texels so that shadows keep still as the camera moves.
  const glm::dmat4 camera_world = glm::inverse(view);
  const glm::dvec3 eye(camera_world[3]);
  const glm::dvec3 forward = -glm::dvec3(camera_world[2]);
  glm::dvec3 ahead(forward.x, forward.y, 0);
  ahead = glm::length(ahead) > 1e-6 ? glm::normalize(ahead) : glm::dvec3(0);
  const double half = 0.5 * cfg.distance, radius = 1.2 * half, depth = 300;
  const glm::dvec3 up = std::abs(d.z) > 0.99 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1);
  const glm::dmat4 light_view = glm::lookAt(glm::dvec3(0), d, up);
  glm::dvec3 c(light_view * glm::dvec4(eye + ahead * half, 1));
  const double texel = 2 * radius / size;
  c.x = std::floor(c.x / texel) * texel;
  c.y = std::floor(c.y / texel) * texel;
  const glm::dmat4 light_clip = glm::ortho(c.x - radius, c.x + radius, c.y - radius, c.y + radius,
                                           -c.z - depth, -c.z + depth) *
                                light_view;

  const ViewFrustum frustum(spec);
  const double lowest_seen = eye.z - spec.far_clip;

  glBindFramebuffer(GL_FRAMEBUFFER, shadow_fbo);
  glViewport(0, 0, size, size);
  const float far_depth = 1.0f;
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glClearBufferfv(GL_DEPTH, 0, &far_depth);
  glUseProgram(shadow_program.id);
  // Only the faces turned away from the light: surfaces facing it do not shadow themselves.
  glEnable(GL_CULL_FACE);
  glFrontFace(GL_CCW);
  glCullFace(GL_FRONT);
  bool culling = true;
  int bound_mesh = -1;
  const auto& instances = scene.instances();
  for (size_t i = 0; i < instances.size(); ++i) {
    const Scene::Instance& inst = instances[i];
    if (!inst.visible || !inst.casts_shadows) continue;
    const Scene::Bounds& b = scene.mesh_bounds()[inst.mesh];
    const glm::dmat4 world = glm::make_mat4(inst.world_from_object.data());
    const double scale =
        std::max({glm::length(glm::dvec3(world[0])), glm::length(glm::dvec3(world[1])),
                  glm::length(glm::dvec3(world[2]))});
    const double r = b.radius * scale;
    const glm::dvec3 lc(light_view * world * glm::dvec4(b.centre[0], b.centre[1], b.centre[2], 1));
    if (std::abs(lc.x - c.x) > radius + r || std::abs(lc.y - c.y) > radius + r ||
        std::abs(lc.z - c.z) > depth + r)
      continue;
    // Its shadow: the bounding sphere swept along the light down to the lowest point the
    // camera can see; skipped when that misses the view.
    const glm::dvec3 wc(world * glm::dvec4(b.centre[0], b.centre[1], b.centre[2], 1));
    const double drop = std::clamp((wc.z + r - lowest_seen) / -d.z, 0.0, 2 * depth);
    if (frustum.misses_capsule(glm::dvec3(view * glm::dvec4(wc, 1)),
                               glm::dvec3(view * glm::dvec4(wc + drop * d, 1)), r))
      continue;
    int mesh = inst.mesh;
    for (const Scene::Lod& lod : scene.mesh_lods()[inst.mesh]) {
      if (lod.error * scale > texel) break;
      mesh = lod.mesh;
    }
    if (inst.material.double_sided == culling) {
      culling = !inst.material.double_sided;
      culling ? glEnable(GL_CULL_FACE) : glDisable(GL_CULL_FACE);
    }
    if (mesh != bound_mesh) {
      glBindVertexArray(gpu.meshes[mesh].vao);
      bound_mesh = mesh;
    }
    glUniformMatrix4fv(shadow_program.mvp, 1, GL_FALSE,
                       glm::value_ptr(glm::mat4(light_clip * world)));
    glDrawElements(GL_TRIANGLES, gpu.meshes[mesh].index_count, GL_UNSIGNED_INT, nullptr);
  }
  glBindVertexArray(0);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  // Eye space -> world -> the light's clip space -> the map's [0, 1] cube.
  const glm::dmat4 to_unit = glm::translate(glm::dmat4(1.0), glm::dvec3(0.5)) *
                             glm::scale(glm::dmat4(1.0), glm::dvec3(0.5));
  shadow_matrix = glm::mat4(to_unit * light_clip * camera_world);
  shadow_region = ShadowRegion{true, light_view, c, radius, depth};
  shadow_bias = glm::vec2(static_cast<float>(1.5 * texel), static_cast<float>(0.05 / (2 * depth)));
  return true;
}

void Renderer::Impl::draw_sky(const Sky& s, const Pose& camera_world_pose, const CameraSpec& spec) {
  if (!sky.id) sky = build_sky_program();
  // The camera's axes in the world (SDF: x forward, y left, z up), scaled so that the ray
  // through a pixel at normalised device coordinates (x, y) is forward + x right + y up.
  // The projection is flipped (rows top first): device y = +1 is the image's bottom.
  const double tx = std::tan(spec.hfov / 2);
  const double ty = tx * spec.height / spec.width;
  auto axis = [&](int c, double scale) {  // column c of the rotation (column-major pose)
    glm::vec3 v;
    for (int r = 0; r < 3; ++r) v[r] = static_cast<float>(scale * camera_world_pose[4 * c + r]);
    return v;
  };
  const glm::vec3 forward = axis(0, 1.0), right = axis(1, -tx), up = axis(2, -ty);
  const GLenum colour_only[3] = {GL_COLOR_ATTACHMENT0, GL_NONE, GL_NONE};
  glDrawBuffers(3, colour_only);
  glDepthFunc(GL_LEQUAL);
  glDepthMask(GL_FALSE);
  glDisable(GL_CULL_FACE);
  glUseProgram(sky.id);
  glUniform3fv(sky.forward, 1, &forward[0]);
  glUniform3fv(sky.right, 1, &right[0]);
  glUniform3fv(sky.up, 1, &up[0]);
  glUniform3fv(sky.horizon, 1, s.horizon.data());
  glUniform3fv(sky.zenith, 1, s.zenith.data());
  glBindVertexArray(sky.vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glEnable(GL_CULL_FACE);
}

// Rain or snow over the colour image only (depth and ids keep the scene's).
void Renderer::Impl::draw_precipitation(const Atmosphere& a, int width, int height) {
  // A new pattern for each frame time, the same for the same seed and time.
  const uint64_t ms = static_cast<uint64_t>(std::llround(a.time * 1000.0));
  PrecipitationParams params;
  params.width = width;
  params.height = height;
  params.amount = a.precipitation;
  params.snow = a.snow;
  params.slant = a.fall_slant;
  params.seed = a.seed * 0x9e3779b9u ^ static_cast<uint32_t>(ms * 0x85ebca6bULL) ^
                static_cast<uint32_t>(ms >> 32);
  make_precipitation(params, &precipitation_vertices);
  if (precipitation_vertices.empty()) return;
  if (!precipitation.id) precipitation = build_precipitation_program();
  const GLenum colour_only[3] = {GL_COLOR_ATTACHMENT0, GL_NONE, GL_NONE};
  glDrawBuffers(3, colour_only);
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glDisable(GL_CULL_FACE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glUseProgram(precipitation.id);
  glUniform2f(precipitation.size, static_cast<float>(width), static_cast<float>(height));
  glUniform1i(precipitation.snow, a.snow ? 1 : 0);
  glBindVertexArray(precipitation.vao);
  glBindBuffer(GL_ARRAY_BUFFER, precipitation.vbo);
  glBufferData(GL_ARRAY_BUFFER,
               static_cast<GLsizeiptr>(precipitation_vertices.size() * sizeof(PrecipitationVertex)),
               precipitation_vertices.data(), GL_STREAM_DRAW);
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(precipitation_vertices.size()));
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glEnable(GL_CULL_FACE);
}

Renderer::Renderer() : impl_(std::make_unique<Impl>()) {
  // llvmpipe allocates its per-frame bins afresh each frame; returned to the system they
  // would fault in again every frame (4x slower at 100k triangles).
  tune_allocator_for_frames();
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &impl_->max_size);
}

Renderer::~Renderer() = default;

const RenderStats& Renderer::last_stats() const { return impl_->stats; }

void Renderer::set_per_vertex_lighting_below(double pixels_per_triangle) {
  impl_->per_vertex_below = pixels_per_triangle;
}

void Renderer::set_lod_pixel_error(double pixels) { impl_->lod_pixel_error = pixels; }

const std::string& Renderer::description() const { return impl_->context.description(); }

void Renderer::render(const Scene& scene, const Pose& camera_world_pose, const CameraSpec& spec,
                      Frame* out, bool want_depth, bool want_boxes) {
  check_spec(spec);
  if (!out) throw std::invalid_argument("Renderer::render: no Frame to render into");
  Impl& s = *impl_;
  s.context.make_current();
  if (spec.width > s.max_size || spec.height > s.max_size) {
    throw std::invalid_argument("Renderer::render: CameraSpec size " + std::to_string(spec.width) +
                                "x" + std::to_string(spec.height) + " exceeds the GPU's limit " +
                                std::to_string(s.max_size));
  }
  const int w = spec.width, h = spec.height;
  const RenderTarget& target = s.targets.get(w, h);
  const GpuScene& gpu = s.scenes.sync(scene);
  ProgramKey key;
  for (const Light& l : scene.lights()) {
    key.lights += l.type == Light::kDirectional ? 'D' : l.type == Light::kPoint ? 'P' : 'S';
  }
  key.depth = want_depth;
  key.ids = want_boxes;
  key.fog = scene.atmosphere().fog();
  key.surface_weather = scene.atmosphere().surface_weather();
  const glm::dmat4 view = glm::inverse(glm::make_mat4(camera_world_pose.data()) * kSdfFromGlCamera);
  s.shadow_region.valid = false;
  if (scene.shadows().enabled) {
    const auto& lights = scene.lights();
    for (int i = 0; i < static_cast<int>(lights.size()); ++i) {
      if (lights[i].type != Light::kDirectional) continue;
      if (s.render_shadow_map(scene, i, view, spec, gpu)) {
        key.shadow_light = i;
        glActiveTexture(GL_TEXTURE1);
        glBindTexture(GL_TEXTURE_2D, s.shadow_texture);
      }
      break;
    }
  }

  glBindFramebuffer(GL_FRAMEBUFFER, target.fbo);
  glViewport(0, 0, w, h);
  const GLenum none = GL_NONE;
  const GLenum buffers[3] = {GL_COLOR_ATTACHMENT0, want_depth ? GL_COLOR_ATTACHMENT1 : none,
                             want_boxes ? GL_COLOR_ATTACHMENT2 : none};
  glDrawBuffers(3, buffers);
  glDisable(GL_BLEND);
  glDisable(GL_DITHER);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glFrontFace(GL_CW);  // counter-clockwise faces turn clockwise under the flipped projection
  const Rgba& bg = scene.background();
  const float background[4] = {bg[0], bg[1], bg[2], 1.0f};
  const float infinity[4] = {std::numeric_limits<float>::infinity(), 0, 0, 0};
  const float zero[4] = {0, 0, 0, 0};
  const float far_depth = 1.0f;
  glClearBufferfv(GL_COLOR, 0, background);
  if (want_depth) glClearBufferfv(GL_COLOR, 1, infinity);
  if (want_boxes) glClearBufferfv(GL_COLOR, 2, zero);
  glClearBufferfv(GL_DEPTH, 0, &far_depth);

  glActiveTexture(GL_TEXTURE0);
  s.collect_draws(scene, view, spec);
  s.draw(key, scene, view, spec, gpu);
  if (scene.sky().gradient) s.draw_sky(scene.sky(), camera_world_pose, spec);
  if (scene.atmosphere().precipitation > 0) s.draw_precipitation(scene.atmosphere(), w, h);

  // Read back. Rows come top first thanks to the flipped projection.
  const size_t pixels = static_cast<size_t>(w) * h;
  out->width = w;
  out->height = h;
  std::vector<uint8_t>& rgba = out->keep_rgba ? out->rgba : s.rgba;
  rgba.resize(pixels * 4);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  if (out->keep_rgba) {
    out->rgb.clear();
  } else {
    out->rgb.resize(pixels * 3);
    rgba_to_rgb(rgba.data(), out->rgb.data(), pixels);
  }
  if (want_depth) {
    out->depth.resize(pixels);
    glReadBuffer(GL_COLOR_ATTACHMENT1);
    if (target.distance_read_format == GL_RED) {
      glReadPixels(0, 0, w, h, GL_RED, GL_FLOAT, out->depth.data());
    } else {
      s.distance_rgba.resize(pixels * 4);
      glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, s.distance_rgba.data());
      for (size_t i = 0; i < pixels; ++i) out->depth[i] = s.distance_rgba[4 * i];
    }
  } else {
    out->depth.clear();
  }
  if (want_boxes) {
    s.ids.resize(pixels);
    glReadBuffer(GL_COLOR_ATTACHMENT2);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, s.ids.data());
    boxes_from_ids(s.ids.data(), w, h, scene, &out->boxes, s.instance_distance.data());
    full_extents(scene, view, spec, &out->boxes);
    if (out->keep_ids) {
      out->model_ids.resize(pixels);
      const auto& instances = scene.instances();
      for (size_t p = 0; p < pixels; ++p) {
        const uint32_t v = s.ids[p];
        out->model_ids[p] = v != 0 && v <= instances.size() ? instances[v - 1].model_id : 0;
      }
    } else {
      out->model_ids.clear();
    }
  } else {
    out->boxes.clear();
    out->model_ids.clear();
  }
  if (const GLenum error = glGetError(); error != GL_NO_ERROR) {
    char code[16];
    std::snprintf(code, sizeof code, "0x%04x", error);
    throw std::runtime_error(std::string("Renderer::render: OpenGL ES error ") + code);
  }
}

}  // namespace convoy::render
