#include "render/gl_program.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace convoy::render {
namespace {

const char* kVertexShader = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
uniform mat4 u_model_view;
uniform mat3 u_normal_matrix;
uniform mat4 u_projection;
out vec3 v_position;  // eye space
out vec3 v_normal;
out vec2 v_uv;
void main() {
  vec4 p = u_model_view * vec4(a_position, 1.0);
  v_position = p.xyz;
  v_normal = u_normal_matrix * a_normal;
  v_uv = a_uv;
  gl_Position = u_projection * p;
}
)";

// Light i: position.w is the type (0 directional, 1 point, 2 spot), direction.w the range,
// attenuation = (constant, linear, quadratic), spot = (cos(outer/2),
// 1 / (cos(inner/2) - cos(outer/2)), falloff).
const char* kFragmentShader = R"(
precision highp float;
in vec3 v_position;
in vec3 v_normal;
in vec2 v_uv;
uniform vec4 u_diffuse;
uniform vec4 u_ambient;
uniform vec4 u_specular;
uniform vec4 u_emissive;
uniform float u_shininess;
uniform bool u_textured;
uniform bool u_double_sided;
uniform sampler2D u_texture;
uniform vec3 u_scene_ambient;
uniform int u_light_count;
uniform vec4 u_light_position[MAX_LIGHTS];
uniform vec4 u_light_direction[MAX_LIGHTS];
uniform vec3 u_light_diffuse[MAX_LIGHTS];
uniform vec3 u_light_specular[MAX_LIGHTS];
uniform vec3 u_light_attenuation[MAX_LIGHTS];
uniform vec3 u_light_spot[MAX_LIGHTS];
layout(location = 0) out vec4 out_color;
#ifdef WITH_DEPTH
layout(location = 1) out vec4 out_depth;
#endif
#ifdef WITH_IDS
uniform vec4 u_instance_id;
layout(location = 2) out vec4 out_id;
#endif

void main() {
  vec3 n = normalize(v_normal);
  if (u_double_sided && !gl_FrontFacing) n = -n;
  vec3 to_eye = normalize(-v_position);
  vec3 tex = u_textured ? texture(u_texture, v_uv).rgb : vec3(1.0);
  vec3 kd = u_diffuse.rgb * tex;
  vec3 color = u_emissive.rgb + u_scene_ambient * u_ambient.rgb * tex;
  for (int i = 0; i < u_light_count; ++i) {
    vec4 lp = u_light_position[i];
    vec4 ld = u_light_direction[i];
    vec3 l;
    float gain = 1.0;
    if (lp.w == 0.0) {
      l = -ld.xyz;
    } else {
      vec3 d = lp.xyz - v_position;
      float dist = length(d);
      l = d / max(dist, 1e-6);
      vec3 a = u_light_attenuation[i];
      gain = dist > ld.w ? 0.0 : 1.0 / max(a.x + (a.y + a.z * dist) * dist, 1e-6);
      if (lp.w == 2.0) {
        vec3 s = u_light_spot[i];
        float rho = dot(-l, ld.xyz);
        gain *= rho < s.x ? 0.0 : pow(clamp((rho - s.x) * s.y, 1e-6, 1.0), s.z);
      }
    }
    float ndl = dot(n, l);
    if (ndl <= 0.0 || gain <= 0.0) continue;
    float ndh = max(dot(n, normalize(l + to_eye)), 1e-6);
    color += gain * (u_light_diffuse[i] * kd * ndl +
                     u_light_specular[i] * u_specular.rgb * pow(ndh, u_shininess));
  }
  out_color = vec4(color, 1.0);
#ifdef WITH_DEPTH
  out_depth = vec4(-v_position.z, 0.0, 0.0, 1.0);
#endif
#ifdef WITH_IDS
  out_id = u_instance_id;
#endif
}
)";

GLuint compile(GLenum stage, const std::string& source) {
  GLuint shader = glCreateShader(stage);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(length + 1, '\0');
    glGetShaderInfoLog(shader, length, nullptr, log.data());
    glDeleteShader(shader);
    throw std::runtime_error(std::string("render: ") +
                             (stage == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                             " shader does not compile: " + log.data());
  }
  return shader;
}

}  // namespace

SurfaceProgram build_surface_program(bool with_depth, bool with_ids, int max_lights) {
  std::string header = "#version 300 es\n#define MAX_LIGHTS " + std::to_string(max_lights) + "\n";
  if (with_depth) header += "#define WITH_DEPTH\n";
  if (with_ids) header += "#define WITH_IDS\n";
  const GLuint vs = compile(GL_VERTEX_SHADER, header + kVertexShader);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, header + kFragmentShader);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  SurfaceProgram p;
  p.id = glCreateProgram();
  glAttachShader(p.id, vs);
  glAttachShader(p.id, fs);
  glLinkProgram(p.id);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(p.id, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetProgramiv(p.id, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(length + 1, '\0');
    glGetProgramInfoLog(p.id, length, nullptr, log.data());
    glDeleteProgram(p.id);
    throw std::runtime_error(std::string("render: shader program does not link: ") + log.data());
  }
  auto at = [&](const char* name) { return glGetUniformLocation(p.id, name); };
  p.model_view = at("u_model_view");
  p.normal_matrix = at("u_normal_matrix");
  p.projection = at("u_projection");
  p.instance_id = at("u_instance_id");
  p.diffuse = at("u_diffuse");
  p.ambient = at("u_ambient");
  p.specular = at("u_specular");
  p.emissive = at("u_emissive");
  p.shininess = at("u_shininess");
  p.textured = at("u_textured");
  p.double_sided = at("u_double_sided");
  p.scene_ambient = at("u_scene_ambient");
  p.light_count = at("u_light_count");
  p.light_position = at("u_light_position");
  p.light_direction = at("u_light_direction");
  p.light_diffuse = at("u_light_diffuse");
  p.light_specular = at("u_light_specular");
  p.light_attenuation = at("u_light_attenuation");
  p.light_spot = at("u_light_spot");
  glUseProgram(p.id);
  glUniform1i(at("u_texture"), 0);
  return p;
}

void destroy_program(SurfaceProgram* program) {
  if (program->id) glDeleteProgram(program->id);
  program->id = 0;
}

}  // namespace convoy::render
