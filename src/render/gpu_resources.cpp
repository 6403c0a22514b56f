#include "render/gpu_resources.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

namespace convoy::render {
namespace {

constexpr int kFloatsPerVertex = 8;  // position, normal, uv

GpuMesh upload_mesh(const MeshData& mesh) {
  const size_t n = mesh.vertex_count();
  std::vector<float> interleaved(n * kFloatsPerVertex, 0.0f);
  for (size_t v = 0; v < n; ++v) {
    float* out = &interleaved[v * kFloatsPerVertex];
    std::memcpy(out, &mesh.positions[3 * v], 3 * sizeof(float));
    std::memcpy(out + 3, &mesh.normals[3 * v], 3 * sizeof(float));
    if (!mesh.uvs.empty()) std::memcpy(out + 6, &mesh.uvs[2 * v], 2 * sizeof(float));
  }
  GpuMesh g;
  g.index_count = static_cast<GLsizei>(mesh.indices.size());
  glGenVertexArrays(1, &g.vao);
  glBindVertexArray(g.vao);
  glGenBuffers(1, &g.vbo);
  glBindBuffer(GL_ARRAY_BUFFER, g.vbo);
  glBufferData(GL_ARRAY_BUFFER, interleaved.size() * sizeof(float), interleaved.data(),
               GL_STATIC_DRAW);
  glGenBuffers(1, &g.ibo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.ibo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, mesh.indices.size() * sizeof(uint32_t), mesh.indices.data(),
               GL_STATIC_DRAW);
  const GLsizei stride = kFloatsPerVertex * sizeof(float);
  const GLint sizes[3] = {3, 3, 2};
  const size_t offsets[3] = {0, 3 * sizeof(float), 6 * sizeof(float)};
  for (GLuint a = 0; a < 3; ++a) {
    glEnableVertexAttribArray(a);
    glVertexAttribPointer(a, sizes[a], GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(offsets[a]));
  }
  glBindVertexArray(0);
  return g;
}

GLuint upload_texture(const Scene::Texture& t) {
  // Scene textures run top row first; GL's t = 0 is the first row given, and mesh uvs put
  // v = 0 at the bottom of the image, so rows go up bottom first.
  const size_t row = static_cast<size_t>(t.width) * 4;
  std::vector<uint8_t> flipped(t.rgba.size());
  for (int y = 0; y < t.height; ++y) {
    std::memcpy(&flipped[y * row], &t.rgba[(t.height - 1 - y) * row], row);
  }
  GLuint id = 0;
  glGenTextures(1, &id);
  glBindTexture(GL_TEXTURE_2D, id);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, t.width, t.height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
               flipped.data());
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  return id;
}

void release(GpuScene* s) {
  for (GpuMesh& m : s->meshes) {
    glDeleteVertexArrays(1, &m.vao);
    glDeleteBuffers(1, &m.vbo);
    glDeleteBuffers(1, &m.ibo);
  }
  if (!s->textures.empty()) {
    glDeleteTextures(static_cast<GLsizei>(s->textures.size()), s->textures.data());
  }
  s->meshes.clear();
  s->textures.clear();
}

void release(RenderTarget* t) {
  glDeleteFramebuffers(1, &t->fbo);
  const GLuint buffers[4] = {t->color, t->distance, t->ids, t->depth_buffer};
  glDeleteRenderbuffers(4, buffers);
}

}  // namespace

GpuSceneCache::~GpuSceneCache() {
  for (auto& s : scenes_) release(s.get());
}

const GpuScene& GpuSceneCache::sync(const Scene& scene) {
  auto it = std::find_if(scenes_.begin(), scenes_.end(),
                         [&](const auto& s) { return s->uid == scene.uid(); });
  if (it == scenes_.end()) {
    if (scenes_.size() >= kMaxScenes) {
      auto oldest =
          std::min_element(scenes_.begin(), scenes_.end(),
                           [](const auto& a, const auto& b) { return a->last_use < b->last_use; });
      release(oldest->get());
      scenes_.erase(oldest);
    }
    scenes_.push_back(std::make_unique<GpuScene>());
    scenes_.back()->uid = scene.uid();
    it = scenes_.end() - 1;
  }
  GpuScene& gpu = **it;
  gpu.last_use = ++clock_;
  // Scenes only ever grow, so what is new is what lies past the uploaded count.
  for (size_t i = gpu.meshes.size(); i < scene.meshes().size(); ++i) {
    gpu.meshes.push_back(upload_mesh(scene.meshes()[i]));
  }
  for (size_t i = gpu.textures.size(); i < scene.textures().size(); ++i) {
    gpu.textures.push_back(upload_texture(scene.textures()[i]));
  }
  return gpu;
}

RenderTargetCache::~RenderTargetCache() {
  for (RenderTarget& t : targets_) release(&t);
}

const RenderTarget& RenderTargetCache::get(int width, int height) {
  auto it = std::find_if(targets_.begin(), targets_.end(), [&](const RenderTarget& t) {
    return t.width == width && t.height == height;
  });
  if (it != targets_.end()) {
    std::rotate(it, it + 1, targets_.end());  // most recently used last
    return targets_.back();
  }
  if (targets_.size() >= kMaxTargets) {
    release(&targets_.front());
    targets_.erase(targets_.begin());
  }
  RenderTarget t;
  t.width = width;
  t.height = height;
  glGenFramebuffers(1, &t.fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, t.fbo);
  GLuint buffers[4];
  glGenRenderbuffers(4, buffers);
  t.color = buffers[0];
  t.distance = buffers[1];
  t.ids = buffers[2];
  t.depth_buffer = buffers[3];
  const GLenum formats[4] = {GL_RGBA8, GL_R32F, GL_RGBA8, GL_DEPTH_COMPONENT24};
  const GLenum attachments[4] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                                 GL_DEPTH_ATTACHMENT};
  for (int i = 0; i < 4; ++i) {
    glBindRenderbuffer(GL_RENDERBUFFER, buffers[i]);
    glRenderbufferStorage(GL_RENDERBUFFER, formats[i], width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachments[i], GL_RENDERBUFFER, buffers[i]);
  }
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    release(&t);
    char code[16];
    std::snprintf(code, sizeof code, "0x%04x", status);
    throw std::runtime_error("render: cannot make a " + std::to_string(width) + "x" +
                             std::to_string(height) + " framebuffer (status " + code +
                             "); R32F colour buffers need EXT_color_buffer_float");
  }
  glReadBuffer(GL_COLOR_ATTACHMENT1);
  GLint format = 0, type = 0;
  glGetIntegerv(GL_IMPLEMENTATION_COLOR_READ_FORMAT, &format);
  glGetIntegerv(GL_IMPLEMENTATION_COLOR_READ_TYPE, &type);
  t.distance_read_format = (format == GL_RED && type == GL_FLOAT) ? GL_RED : GL_RGBA;
  targets_.push_back(t);
  return targets_.back();
}

}  // namespace convoy::render
