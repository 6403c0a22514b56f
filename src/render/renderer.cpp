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
#include "render/frustum.h"
#include "render/readback.h"
#include "render/renderer_impl.h"

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

}  // namespace

using renderer_detail::Draw;
using renderer_detail::kFlushEveryTriangles;
using renderer_detail::kPerVertex;
using renderer_detail::kShadowed;
using renderer_detail::kSpecular;
using renderer_detail::kTextured;

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

namespace {

// A cheap first test (a city holds thousands of instances, most of them out of view): the
// bounding sphere's centre taken to eye space point by point rather than through the
// model-view matrix, its radius a little larger for the rounding. An instance it keeps goes
// through the exact test, so the frame is the same as without it.
bool clearly_out_of_view(const ViewFrustum& frustum, const glm::dmat4& view,
                         const Scene::Instance& inst, const Scene::Bounds& b) {
  const glm::dmat4 world = glm::make_mat4(inst.world_from_object.data());
  const glm::dvec3 c = view * (world * glm::dvec4(b.centre[0], b.centre[1], b.centre[2], 1));
  const double scale =
      std::max({glm::length(glm::dvec3(world[0])), glm::length(glm::dvec3(world[1])),
                glm::length(glm::dvec3(world[2]))});
  return frustum.misses_sphere(c, b.radius * scale * (1 + 1e-6) + 1e-6);
}

}  // namespace

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
    if (clearly_out_of_view(frustum, view, inst, b)) continue;
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
