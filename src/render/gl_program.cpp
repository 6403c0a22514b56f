#include "render/gl_program.h"

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace convoy::render {
namespace {

const char* kVertexShader = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_model_view;
uniform mat3 u_normal_matrix;
uniform mat4 u_projection;
out vec3 v_position;  // eye space
out vec3 v_normal;
#ifdef TEXTURED
layout(location = 2) in vec2 a_uv;
out vec2 v_uv;
#endif
void main() {
  vec4 p = u_model_view * vec4(a_position, 1.0);
  v_position = p.xyz;
  v_normal = u_normal_matrix * a_normal;
#ifdef TEXTURED
  v_uv = a_uv;
#endif
  gl_Position = u_projection * p;
}
)";

// Light i (arrays of LIGHTS): position and direction in eye space, direction.w = range,
// attenuation = (constant, linear, quadratic), spot = (cos(outer/2),
// 1 / (cos(inner/2) - cos(outer/2)), falloff).
const char* kFragmentHead = R"(
precision highp float;
in vec3 v_position;
in vec3 v_normal;
uniform vec4 u_diffuse;
uniform vec4 u_ambient;
uniform vec4 u_specular;
uniform vec4 u_emissive;
uniform float u_shininess;
uniform bool u_double_sided;
uniform vec3 u_scene_ambient;
#if LIGHTS > 0
uniform vec3 u_light_position[LIGHTS];
uniform vec4 u_light_direction[LIGHTS];
uniform vec3 u_light_diffuse[LIGHTS];
uniform vec3 u_light_specular[LIGHTS];
uniform vec3 u_light_attenuation[LIGHTS];
uniform vec3 u_light_spot[LIGHTS];
#endif
#ifdef TEXTURED
in vec2 v_uv;
uniform sampler2D u_texture;
#endif
layout(location = 0) out vec4 out_color;
#ifdef DEPTH
layout(location = 1) out vec4 out_depth;
#endif
#ifdef IDS
uniform vec4 u_instance_id;
layout(location = 2) out vec4 out_id;
#endif

vec3 n;
vec3 to_eye;
vec3 kd;

// Diffuse plus Blinn-Phong specular of light i arriving along unit vector l with `gain`.
vec3 shade(int i, vec3 l, float gain) {
  float ndl = dot(n, l);
  float ndh = max(dot(n, normalize(l + to_eye)), 1e-6);
#ifdef NOSPEC
  float spec = 0.0;
#elif defined(SCHLICK)
  float spec = ndl > 0.0 ? ndh / (u_shininess - u_shininess * ndh + ndh) : 0.0;
#else
  float spec = ndl > 0.0 ? pow(ndh, u_shininess) : 0.0;
#endif
  return gain * (u_light_diffuse[i] * kd * max(ndl, 0.0) + u_light_specular[i] * u_specular.rgb * spec);
}

// Attenuated gain of a point or spot light i at distance `dist`.
float attenuation(int i, float dist) {
  vec3 a = u_light_attenuation[i];
  return dist > u_light_direction[i].w ? 0.0 : 1.0 / max(a.x + (a.y + a.z * dist) * dist, 1e-6);
}

vec3 directional(int i) { return shade(i, -u_light_direction[i].xyz, 1.0); }

vec3 point(int i) {
#ifdef NOPOINT
  return vec3(0.0);
#endif
  vec3 d = u_light_position[i] - v_position;
  float dist = length(d);
  return shade(i, d / dist, attenuation(i, dist));
}

vec3 spot(int i) {
  vec3 d = u_light_position[i] - v_position;
  float dist = length(d);
  vec3 l = d / dist;
  vec3 s = u_light_spot[i];
  float rho = dot(-l, u_light_direction[i].xyz);
  float cone = rho < s.x ? 0.0 : pow(clamp((rho - s.x) * s.y, 1e-6, 1.0), s.z);
  return shade(i, l, attenuation(i, dist) * cone);
}

void main() {
#ifdef FLAT
  out_color = u_diffuse;
  return;
#endif
#ifdef NORMAL
  out_color = vec4(normalize(v_normal) * u_diffuse.rgb, 1.0);
  return;
#endif
  n = normalize(v_normal);
  if (u_double_sided && !gl_FrontFacing) n = -n;
  to_eye = normalize(-v_position);
#ifdef TEXTURED
  vec3 tex = texture(u_texture, v_uv).rgb;
#else
  vec3 tex = vec3(1.0);
#endif
  kd = u_diffuse.rgb * tex;
  vec3 color = u_emissive.rgb + u_scene_ambient * u_ambient.rgb * tex;
)";

const char* kFragmentTail = R"(
  out_color = vec4(color, 1.0);
#ifdef DEPTH
  out_depth = vec4(-v_position.z, 0.0, 0.0, 1.0);
#endif
#ifdef IDS
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

SurfaceProgram build_surface_program(const ProgramKey& key) {
  std::string header = "#version 300 es\n#define LIGHTS " + std::to_string(key.lights.size()) + "\n";
  if (key.textured) header += "#define TEXTURED\n";
  if (getenv("DBG")) header += std::string("#define ") + getenv("DBG") + "\n";
  if (key.depth) header += "#define DEPTH\n";
  if (key.ids) header += "#define IDS\n";
  std::string body;
  for (size_t i = 0; i < key.lights.size(); ++i) {
    const char* f = key.lights[i] == 'D' ? "directional" : key.lights[i] == 'P' ? "point" : "spot";
    body += "  color += " + std::string(f) + "(" + std::to_string(i) + ");\n";
  }
  // Without lights the helper functions would index empty arrays: leave them out.
  std::string head = kFragmentHead;
  if (key.lights.empty()) {
    const size_t from = head.find("// Diffuse plus"), to = head.find("void main()");
    head.erase(from, to - from);
  }
  const GLuint vs = compile(GL_VERTEX_SHADER, header + kVertexShader);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, header + head + body + kFragmentTail);
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
  p.double_sided = at("u_double_sided");
  p.scene_ambient = at("u_scene_ambient");
  p.light_position = at("u_light_position");
  p.light_direction = at("u_light_direction");
  p.light_diffuse = at("u_light_diffuse");
  p.light_specular = at("u_light_specular");
  p.light_attenuation = at("u_light_attenuation");
  p.light_spot = at("u_light_spot");
  glUseProgram(p.id);
  if (key.textured) glUniform1i(at("u_texture"), 0);
  return p;
}

void destroy_program(SurfaceProgram* program) {
  if (program->id) glDeleteProgram(program->id);
  program->id = 0;
}

}  // namespace convoy::render
