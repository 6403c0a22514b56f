// The renderer's shader programs (internal): Blinn-Phong surfaces, one program per variant.
//
// llvmpipe runs every branch of a shader for every pixel, so instead of one general shader
// each combination of lights, texturing and outputs gets its own program with only the code
// it needs: lights unrolled by type, no texture lookup without a texture. Every fragment
// shader is highp: llvmpipe's mediump arithmetic is several times slower (the sky's gradient
// cost 6-8 ms of CPU a 736x480 frame in mediump, about 1 in highp).
//
// Lighting is computed in eye space, per pixel; or per vertex for meshes whose triangles
// cover only a few pixels each, where it looks the same (mean difference under 2/255): there
// llvmpipe would shade every tiny triangle's whole 4x4 pixel block (about 12% faster on a
// 100k-triangle scene of small spheres).
//
// Outputs: location 0 the lit colour (RGBA8), location 1 the distance along the optical axis
// in metres (R32F, with depth), location 2 the instance id as RGBA8 bytes (with ids).
#pragma once

#include <GLES3/gl3.h>

#include <string>

namespace convoy::render {

struct ProgramKey {
  std::string lights;  // one letter per light, in order: D directional, P point, S spot
  bool textured = false;
  bool depth = false;
  bool ids = false;
  bool per_vertex = false;  // lighting in the vertex shader
  bool specular = true;     // false: the material has no specular colour (no highlights to compute)
  bool fog = false;         // Atmosphere::fog()
  bool surface_weather = false;  // Atmosphere::surface_weather() (per-pixel programs only)
  int shadow_light = -1;         // the light whose shadow map is bound (texture unit 1), or -1

  auto operator<=>(const ProgramKey&) const = default;
};

struct SurfaceProgram {
  GLuint id = 0;
  // Per draw.
  GLint model_view = -1, normal_matrix = -1, instance_id = -1;
  GLint diffuse = -1, ambient = -1, specular = -1, emissive = -1, shininess = -1;
  GLint textured_emissive = -1;
  GLint double_sided = -1;
  // Per frame.
  GLint projection = -1, scene_ambient = -1;
  GLint light_position = -1, light_direction = -1, light_diffuse = -1, light_specular = -1;
  GLint light_attenuation = -1, light_spot = -1;
  GLint fog_k = -1, fog_color = -1, up = -1, wetness = -1, snow = -1, sky = -1;
  GLint shadow_matrix = -1, shadow_bias = -1;
};

// Depth only, for shadow maps: u_mvp takes object space to the light's clip space.
struct ShadowProgram {
  GLuint id = 0;
  GLint mvp = -1;
};
ShadowProgram build_shadow_program();

// The sky behind the scene: a full-screen triangle at the far plane, drawn where nothing
// else is, from the horizon's colour to the zenith's by the view ray's elevation.
struct SkyProgram {
  GLuint id = 0, vao = 0;
  GLint forward = -1, right = -1, up = -1, horizon = -1, zenith = -1;
};
SkyProgram build_sky_program();

// Draws rain streaks or snow flakes (precipitation.h's quads) over the image, blended.
struct PrecipitationProgram {
  GLuint id = 0, vao = 0, vbo = 0;
  GLint size = -1, snow = -1;
};
PrecipitationProgram build_precipitation_program();

// Compiles and links the program; throws std::runtime_error with the driver's log on failure.
SurfaceProgram build_surface_program(const ProgramKey& key);
void destroy_program(SurfaceProgram* program);

}  // namespace convoy::render
