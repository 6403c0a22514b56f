// Renderer: the sun's shadow map (Scene::shadows), around what the camera sees.
#include <GLES3/gl3.h>

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <numbers>

#include "render/frustum.h"
#include "render/renderer_impl.h"

namespace convoy::render {

using renderer_detail::ShadowRegion;

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
    const glm::dvec4 centre(b.centre[0], b.centre[1], b.centre[2], 1);
    // First without the matrix product (most of a city is out of the map), with a margin for
    // the rounding; what it keeps goes through the exact test below.
    const glm::dvec3 rough(light_view * (world * centre));
    const double margin = 1e-6 * (1 + std::abs(rough.x) + std::abs(rough.y) + std::abs(rough.z));
    if (std::abs(rough.x - c.x) > radius + r + margin ||
        std::abs(rough.y - c.y) > radius + r + margin ||
        std::abs(rough.z - c.z) > depth + r + margin)
      continue;
    const glm::dvec3 lc(light_view * world * centre);
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

}  // namespace convoy::render
