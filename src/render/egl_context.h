// A headless OpenGL ES 3 context through EGL (internal to the renderer).
//
// Tries, in order: Mesa's surfaceless platform (llvmpipe, or a GPU's render node), the EGL
// device platform (e.g. NVIDIA without a display), the default display. No window system
// and no surface: rendering goes to framebuffer objects.
#pragma once

#include <EGL/egl.h>

#include <string>

namespace convoy::render {

class EglContext {
 public:
  // Throws std::runtime_error listing what each platform answered if none gives a context.
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  // Makes the context current on the calling thread (cheap when it already is). Throws if
  // that fails, e.g. while it is current on another thread.
  void make_current();
  // "OpenGL ES 3.2 Mesa 22.3.6, llvmpipe (LLVM 15.0.6, 256 bits), EGL platform surfaceless"
  const std::string& description() const { return description_; }

 private:
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::string description_;
};

}  // namespace convoy::render
