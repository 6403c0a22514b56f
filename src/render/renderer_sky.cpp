// Renderer: the sky where nothing was drawn, and precipitation over the frame.
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

}  // namespace convoy::render
