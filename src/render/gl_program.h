// The renderer's shader program (internal): Blinn-Phong surfaces with optional extra outputs.
//
// Outputs: location 0 the lit colour (RGBA8), location 1 the distance along the optical axis
// in metres (R32F, when built with depth), location 2 the instance id packed into RGBA8
// bytes (when built with ids). Lighting is computed in eye space, per pixel.
#pragma once

#include <GLES3/gl3.h>

namespace convoy::render {

struct SurfaceProgram {
  GLuint id = 0;
  // Per draw.
  GLint model_view = -1, normal_matrix = -1, instance_id = -1;
  GLint diffuse = -1, ambient = -1, specular = -1, emissive = -1, shininess = -1;
  GLint textured = -1, double_sided = -1;
  // Per frame.
  GLint projection = -1, scene_ambient = -1, light_count = -1;
  GLint light_position = -1, light_direction = -1, light_diffuse = -1, light_specular = -1;
  GLint light_attenuation = -1, light_spot = -1;
};

// Compiles and links the program; throws std::runtime_error with the driver's log on failure.
// `max_lights` sizes the light arrays.
SurfaceProgram build_surface_program(bool with_depth, bool with_ids, int max_lights);
void destroy_program(SurfaceProgram* program);

}  // namespace convoy::render
