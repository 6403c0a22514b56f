// GPU copies of scenes and offscreen framebuffers (internal to the renderer).
//
// Both caches need the renderer's context current when used or destroyed.
#pragma once

#include <GLES3/gl3.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "render/scene.h"

namespace convoy::render {

struct GpuMesh {
  GLuint vao = 0, vbo = 0, ibo = 0;
  GLsizei index_count = 0;
};

struct GpuScene {
  uint64_t uid = 0;
  std::vector<GpuMesh> meshes;
  std::vector<GLuint> textures;
  uint64_t last_use = 0;
};

// The GPU copies of the last few Scenes rendered (least recently used ones are dropped).
// Meshes and textures are uploaded once, the first time their Scene is rendered after they
// were added.
class GpuSceneCache {
 public:
  static constexpr size_t kMaxScenes = 4;
  GpuSceneCache() = default;
  GpuSceneCache(const GpuSceneCache&) = delete;
  GpuSceneCache& operator=(const GpuSceneCache&) = delete;
  ~GpuSceneCache();

  const GpuScene& sync(const Scene& scene);

 private:
  std::vector<std::unique_ptr<GpuScene>> scenes_;
  uint64_t clock_ = 0;
};

// An offscreen framebuffer: colour (RGBA8), distance (R32F), instance ids (RGBA8) and a
// depth buffer, as colour attachments 0, 1 and 2.
struct RenderTarget {
  int width = 0, height = 0;
  GLuint fbo = 0, color = 0, distance = 0, ids = 0, depth_buffer = 0;
  // How glReadPixels reads the distance attachment: GL_RED, or GL_RGBA where the
  // implementation allows only that.
  GLenum distance_read_format = GL_RED;
};

// Framebuffers by resolution, kept for reuse (the least recently used beyond a few go).
class RenderTargetCache {
 public:
  static constexpr size_t kMaxTargets = 8;
  RenderTargetCache() = default;
  RenderTargetCache(const RenderTargetCache&) = delete;
  RenderTargetCache& operator=(const RenderTargetCache&) = delete;
  ~RenderTargetCache();

  // Throws std::runtime_error if the framebuffer cannot be made.
  const RenderTarget& get(int width, int height);

 private:
  std::vector<RenderTarget> targets_;  // most recently used last
};

}  // namespace convoy::render
