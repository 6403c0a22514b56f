#include "render/gl_program.h"

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/precipitation.h"

namespace convoy::render {
namespace {

// Light i (arrays of LIGHTS): position and direction in eye space, direction.w = range,
// attenuation = (constant, linear, quadratic), spot = (cos(outer/2),
// 1 / (cos(inner/2) - cos(outer/2)), falloff). The functions add light i's diffuse and
// specular irradiance at eye-space point p with unit normal n to g_diffuse and g_specular.
const char* kLighting = R"(
#if LIGHTS > 0
uniform vec3 u_light_position[LIGHTS];
uniform vec4 u_light_direction[LIGHTS];
uniform vec3 u_light_diffuse[LIGHTS];
uniform vec3 u_light_specular[LIGHTS];
uniform vec3 u_light_attenuation[LIGHTS];
uniform vec3 u_light_spot[LIGHTS];
uniform float u_shininess;
vec3 g_diffuse = vec3(0.0);
vec3 g_specular = vec3(0.0);

void shade(int i, vec3 p, vec3 n, vec3 l, float gain) {
  float ndl = dot(n, l);
  g_diffuse += (gain * max(ndl, 0.0)) * u_light_diffuse[i];
#ifdef SPECULAR
  float ndh = max(dot(n, normalize(l - normalize(p))), 1e-6);
  float spec = ndl > 0.0 ? pow(ndh, u_shininess) : 0.0;
  g_specular += (gain * spec) * u_light_specular[i];
#endif
}

float attenuation(int i, float dist) {
  vec3 a = u_light_attenuation[i];
  return dist > u_light_direction[i].w ? 0.0 : 1.0 / max(a.x + (a.y + a.z * dist) * dist, 1e-6);
}

#ifdef SHADOW_LIGHT
// The light SHADOW_LIGHT's shadow map: depth-compared with bilinear filtering (2 x 2 PCF),
// looked up a little along the normal (u_shadow_bias.x metres) and closer to the light
// (u_shadow_bias.y, depth units) against self-shadowing. Outside the map: lit.
uniform highp sampler2DShadow u_shadow_map;
uniform vec2 u_shadow_bias;
#ifdef SHADOW_VARYINGS
// Per pixel, the map's coordinates come interpolated from the vertices' (exact: the map's
// projection is affine), the normal's offset with them; g_shadow_side is -1 on the back of a
// double-sided face.
in vec3 v_shadow;
in vec3 v_shadow_normal;
float g_shadow_side = 1.0;
float shadow_gain(vec3 p, vec3 n) {
  vec3 s = v_shadow + (g_shadow_side * u_shadow_bias.x) * v_shadow_normal;
#else
uniform highp mat4 u_shadow_matrix;  // eye space -> the map's [0, 1] cube
float shadow_gain(vec3 p, vec3 n) {
  vec3 s = (u_shadow_matrix * vec4(p + n * u_shadow_bias.x, 1.0)).xyz;
#endif
  if (s.x <= 0.0 || s.x >= 1.0 || s.y <= 0.0 || s.y >= 1.0 || s.z >= 1.0) return 1.0;
  return texture(u_shadow_map, vec3(s.xy, s.z - u_shadow_bias.y));
}
#endif

void directional(int i, vec3 p, vec3 n) {
#ifdef SHADOW_LIGHT
  float gain = i == SHADOW_LIGHT ? shadow_gain(p, n) : 1.0;
#else
  float gain = 1.0;
#endif
  shade(i, p, n, -u_light_direction[i].xyz, gain);
}

void point(int i, vec3 p, vec3 n) {
  vec3 d = u_light_position[i] - p;
  float dist = max(length(d), 1e-6);
  shade(i, p, n, d / dist, attenuation(i, dist));
}

void spot(int i, vec3 p, vec3 n) {
  vec3 d = u_light_position[i] - p;
  float dist = max(length(d), 1e-6);
  vec3 l = d / dist;
  vec3 s = u_light_spot[i];
  float rho = dot(-l, u_light_direction[i].xyz);
  float cone = rho < s.x ? 0.0 : pow(clamp((rho - s.x) * s.y, 1e-6, 1.0), s.z);
  shade(i, p, n, l, attenuation(i, dist) * cone);
}
#else
const vec3 g_diffuse = vec3(0.0);
const vec3 g_specular = vec3(0.0);
#endif
)";

const char* kVertexShader = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_model_view;
uniform mat3 u_normal_matrix;
uniform mat4 u_projection;
#ifdef TEXTURED
layout(location = 2) in vec2 a_uv;
out vec2 v_uv;
#endif
#ifdef PER_VERTEX
uniform vec4 u_diffuse;
uniform vec4 u_ambient;
uniform vec4 u_specular;
uniform vec4 u_emissive;
uniform vec3 u_scene_ambient;
out vec3 v_color;  // the lit colour; times the texture's where textured,
#ifdef TEXTURED
out vec3 v_added;  // plus this
#endif
#else
out vec3 v_normal;
#ifdef SHADOW_LIGHT
uniform highp mat4 u_shadow_matrix;  // eye space -> the map's [0, 1] cube (affine)
out vec3 v_shadow;                   // the vertex in the map
out vec3 v_shadow_normal;            // its unit normal in the map
#endif
#endif
#if defined(DEPTH) || !defined(PER_VERTEX) || defined(FOG)
out vec3 v_position;  // eye space
#endif
LIGHTING_CODE
void main() {
  vec4 p = u_model_view * vec4(a_position, 1.0);
#if defined(DEPTH) || !defined(PER_VERTEX) || defined(FOG)
  v_position = p.xyz;
#endif
  vec3 normal = u_normal_matrix * a_normal;
#ifdef PER_VERTEX
  vec3 n = normalize(normal);
  LIGHT_CALLS
  vec3 modulated = u_scene_ambient * u_ambient.rgb + g_diffuse * u_diffuse.rgb;
  vec3 added = u_emissive.rgb + g_specular * u_specular.rgb;
#ifdef TEXTURED
  v_color = modulated;
  v_added = added;
#else
  v_color = modulated + added;
#endif
#else
  v_normal = normal;
#ifdef SHADOW_LIGHT
  v_shadow = (u_shadow_matrix * p).xyz;
  v_shadow_normal = mat3(u_shadow_matrix) * normalize(normal);
#endif
#endif
#ifdef TEXTURED
  v_uv = a_uv;
#endif
  gl_Position = u_projection * p;
}
)";

const char* kFragmentShader = R"(
precision highp float;
#ifdef PER_VERTEX
in vec3 v_color;
#ifdef TEXTURED
in vec3 v_added;
#endif
#if defined(DEPTH) || defined(FOG)
in vec3 v_position;
#endif
#else
in vec3 v_position;
in vec3 v_normal;
uniform vec4 u_diffuse;
uniform vec4 u_ambient;
uniform vec4 u_specular;
uniform vec4 u_emissive;
uniform vec3 u_scene_ambient;
uniform bool u_double_sided;
#endif
#ifdef TEXTURED
in vec2 v_uv;
uniform sampler2D u_texture;
uniform float u_textured_emissive;  // 1: the texture multiplies the emissive colour too
#ifdef PER_VERTEX
uniform vec4 u_emissive;
#endif
#endif
#ifdef FOG
uniform float u_fog_k;  // 3.912 / visibility
uniform vec3 u_fog_color;
#endif
#ifdef SURFACE_WEATHER
uniform vec3 u_up;  // world up in eye space
uniform float u_wetness;
uniform float u_snow;
uniform vec3 u_sky;
#endif
layout(location = 0) out vec4 out_color;
#ifdef DEPTH
layout(location = 1) out vec4 out_depth;
#endif
#ifdef IDS
uniform vec4 u_instance_id;
layout(location = 2) out vec4 out_id;
#endif
LIGHTING_CODE
void main() {
#ifdef TEXTURED
  vec3 tex = texture(u_texture, v_uv).rgb;
#else
  vec3 tex = vec3(1.0);
#endif
#ifdef PER_VERTEX
#ifdef TEXTURED
  vec3 color = v_color * tex + v_added;
  color += u_textured_emissive * u_emissive.rgb * (tex - 1.0);  // (0 unless asked: unchanged)
#else
  vec3 color = v_color;
#endif
#else
  vec3 color = u_emissive.rgb + u_scene_ambient * u_ambient.rgb * tex;
  vec3 n = normalize(v_normal);
  if (u_double_sided && !gl_FrontFacing) n = -n;
#ifdef SHADOW_VARYINGS
  if (u_double_sided && !gl_FrontFacing) g_shadow_side = -1.0;
#endif
  vec3 p = v_position;
  LIGHT_CALLS
  color += g_diffuse * u_diffuse.rgb * tex + g_specular * u_specular.rgb;
#ifdef TEXTURED
  color += u_textured_emissive * u_emissive.rgb * (tex - 1.0);
#endif
#ifdef SURFACE_WEATHER
  float up = dot(n, u_up);
  if (up > 0.6) {
    // Up-facing surfaces: snow turns them white; water darkens them and mirrors the sky at
    // grazing angles (Schlick's Fresnel term for water).
    float flat_up = smoothstep(0.6, 0.9, up);
    color = mix(color, 0.95 * (u_scene_ambient + g_diffuse), u_snow * flat_up);
    float m = 1.0 - max(dot(n, -normalize(p)), 0.0), m2 = m * m;
    float fresnel = 0.02 + 0.98 * m2 * m2 * m;
    float w = u_wetness * flat_up;
    color = color * (1.0 - 0.45 * w) + (w * fresnel) * u_sky;
  }
#endif
#endif
#ifdef FOG
  color = mix(u_fog_color, color, exp(-u_fog_k * length(v_position)));
#endif
  out_color = vec4(color, 1.0);
#ifdef DEPTH
  out_depth = vec4(-v_position.z, 0.0, 0.0, 1.0);
#endif
#ifdef IDS
  out_id = u_instance_id;
#endif
}
)";

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = 0; (at = text.find(from, at)) != std::string::npos; at += to.size()) {
    text.replace(at, from.size(), to);
  }
  return text;
}

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

// Compiles and links a program of the two stages; throws with the driver's log.
GLuint link(const std::string& vertex, const std::string& fragment) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  const GLuint id = glCreateProgram();
  glAttachShader(id, vs);
  glAttachShader(id, fs);
  glLinkProgram(id);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(id, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetProgramiv(id, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(length + 1, '\0');
    glGetProgramInfoLog(id, length, nullptr, log.data());
    glDeleteProgram(id);
    throw std::runtime_error(std::string("render: shader program does not link: ") + log.data());
  }
  return id;
}

}  // namespace

SurfaceProgram build_surface_program(const ProgramKey& key) {
  std::string header =
      "#version 300 es\n#define LIGHTS " + std::to_string(key.lights.size()) + "\n";
  if (key.textured) header += "#define TEXTURED\n";
  if (key.depth) header += "#define DEPTH\n";
  if (key.ids) header += "#define IDS\n";
  if (key.per_vertex) header += "#define PER_VERTEX\n";
  if (key.specular) header += "#define SPECULAR\n";
  if (key.fog) header += "#define FOG\n";
  if (key.surface_weather && !key.per_vertex) header += "#define SURFACE_WEATHER\n";
  if (key.shadow_light >= 0)
    header += "#define SHADOW_LIGHT " + std::to_string(key.shadow_light) + "\n";
  std::string calls;
  for (size_t i = 0; i < key.lights.size(); ++i) {
    const char* f = key.lights[i] == 'D' ? "directional" : key.lights[i] == 'P' ? "point" : "spot";
    calls += std::string(f) + "(" + std::to_string(i) + ", p.xyz, n);\n  ";
  }
  // The lighting code goes into the stage that lights.
  auto stage = [&](const char* source, bool lights_here, const std::string& more = "") {
    std::string s = replace_all(source, "LIGHTING_CODE", lights_here ? kLighting : "");
    return header + more + replace_all(s, "LIGHT_CALLS", lights_here ? calls : "");
  };
  // Lit per pixel, the shadow map's coordinates come from the vertex shader.
  const bool shadow_varyings = key.shadow_light >= 0 && !key.per_vertex;
  SurfaceProgram p;
  p.id = link(
      stage(kVertexShader, key.per_vertex),
      stage(kFragmentShader, !key.per_vertex, shadow_varyings ? "#define SHADOW_VARYINGS\n" : ""));
  auto at = [&](const char* name) { return glGetUniformLocation(p.id, name); };
  p.model_view = at("u_model_view");
  p.normal_matrix = at("u_normal_matrix");
  p.projection = at("u_projection");
  p.instance_id = at("u_instance_id");
  p.diffuse = at("u_diffuse");
  p.ambient = at("u_ambient");
  p.specular = at("u_specular");
  p.emissive = at("u_emissive");
  p.textured_emissive = at("u_textured_emissive");
  p.shininess = at("u_shininess");
  p.double_sided = at("u_double_sided");
  p.scene_ambient = at("u_scene_ambient");
  p.light_position = at("u_light_position");
  p.light_direction = at("u_light_direction");
  p.light_diffuse = at("u_light_diffuse");
  p.light_specular = at("u_light_specular");
  p.light_attenuation = at("u_light_attenuation");
  p.light_spot = at("u_light_spot");
  p.fog_k = at("u_fog_k");
  p.fog_color = at("u_fog_color");
  p.up = at("u_up");
  p.wetness = at("u_wetness");
  p.snow = at("u_snow");
  p.sky = at("u_sky");
  p.shadow_matrix = at("u_shadow_matrix");
  p.shadow_bias = at("u_shadow_bias");
  glUseProgram(p.id);
  if (key.textured) glUniform1i(at("u_texture"), 0);
  if (key.shadow_light >= 0) glUniform1i(at("u_shadow_map"), 1);
  return p;
}

ShadowProgram build_shadow_program() {
  ShadowProgram p;
  p.id = link(R"(#version 300 es
layout(location = 0) in vec3 a_position;
uniform mat4 u_mvp;
void main() { gl_Position = u_mvp * vec4(a_position, 1.0); }
)",
              R"(#version 300 es
void main() {}
)");
  p.mvp = glGetUniformLocation(p.id, "u_mvp");
  return p;
}

namespace {

// The sky: one triangle covering the screen at the far plane (depth 1, drawn with LEQUAL:
// only where nothing was drawn); the view ray through each corner is forward + x right +
// y up (the camera's axes in the world, scaled by the field of view), interpolated exactly.
const char* kSkyVertexShader = R"(#version 300 es
uniform vec3 u_forward;
uniform vec3 u_right;
uniform vec3 u_up;
out vec3 v_ray;
void main() {
  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  v_ray = u_forward + p.x * u_right + p.y * u_up;
  gl_Position = vec4(p, 1.0, 1.0);
}
)";

const char* kSkyShader = R"(#version 300 es
precision highp float;
uniform vec3 u_horizon;
uniform vec3 u_zenith;
in vec3 v_ray;
out vec4 out_color;
void main() {
  float elevation = max(normalize(v_ray).z, 0.0);
  out_color = vec4(mix(u_horizon, u_zenith, sqrt(elevation)), 1.0);
}
)";

// Rain streaks and snow flakes as small quads made on the CPU (precipitation.h): positions in
// image pixels (row 0 at the top), a local coordinate across the streak or the flake, and the
// particle's opacity. Only the pixels the particles cover are shaded.
const char* kPrecipitationVertexShader = R"(#version 300 es
uniform vec2 u_size;
layout(location = 0) in vec2 a_pixel;
layout(location = 1) in vec3 a_local;  // across x, across y, opacity
out vec3 v_local;
void main() {
  v_local = a_local;
  gl_Position = vec4(2.0 * a_pixel.x / u_size.x - 1.0, 1.0 - 2.0 * a_pixel.y / u_size.y, 0.0, 1.0);
}
)";

const char* kPrecipitationShader = R"(#version 300 es
precision highp float;
uniform bool u_snow;
in vec3 v_local;
out vec4 out_color;
void main() {
  float alpha = u_snow ? v_local.z * (1.0 - smoothstep(0.5, 1.0, length(v_local.xy)))
                       : v_local.z * (1.0 - 0.5 * abs(v_local.x));
  out_color = vec4(u_snow ? vec3(0.96) : vec3(0.8, 0.83, 0.87), alpha);
}
)";

}  // namespace

SkyProgram build_sky_program() {
  SkyProgram p;
  p.id = link(kSkyVertexShader, kSkyShader);
  p.forward = glGetUniformLocation(p.id, "u_forward");
  p.right = glGetUniformLocation(p.id, "u_right");
  p.up = glGetUniformLocation(p.id, "u_up");
  p.horizon = glGetUniformLocation(p.id, "u_horizon");
  p.zenith = glGetUniformLocation(p.id, "u_zenith");
  glGenVertexArrays(1, &p.vao);  // no attributes: the corners come from gl_VertexID
  return p;
}

PrecipitationProgram build_precipitation_program() {
  PrecipitationProgram p;
  p.id = link(kPrecipitationVertexShader, kPrecipitationShader);
  p.size = glGetUniformLocation(p.id, "u_size");
  p.snow = glGetUniformLocation(p.id, "u_snow");
  glGenVertexArrays(1, &p.vao);
  glGenBuffers(1, &p.vbo);
  glBindVertexArray(p.vao);
  glBindBuffer(GL_ARRAY_BUFFER, p.vbo);
  const GLsizei stride = sizeof(PrecipitationVertex);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, stride, nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<const void*>(offsetof(PrecipitationVertex, across_x)));
  glBindVertexArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  return p;
}

void destroy_program(SurfaceProgram* program) {
  if (program->id) glDeleteProgram(program->id);
  program->id = 0;
}

}  // namespace convoy::render
