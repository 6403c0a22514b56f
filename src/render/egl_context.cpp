#include "render/egl_context.h"

#include <EGL/eglext.h>
#include <GLES3/gl3.h>

#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace convoy::render {
namespace {

bool has_extension(const char* list, const char* name) {
  if (!list) return false;
  const size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n) {
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  }
  return false;
}

std::string egl_error() {
  char buf[32];
  std::snprintf(buf, sizeof buf, "EGL error 0x%04x", eglGetError());
  return buf;
}

// Several renderers may share one EGLDisplay (EGL hands out the same handle per platform and
// device); it is terminated when the last of them goes.
std::mutex g_display_mutex;
int g_display_users = 0;

// Initialises `display` and makes an OpenGL ES 3 context current on it without a surface.
// Returns the context, or EGL_NO_CONTEXT with `why` set.
EGLContext try_display(EGLDisplay display, std::string* why) {
  if (display == EGL_NO_DISPLAY) {
    *why = "no display";
    return EGL_NO_CONTEXT;
  }
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) {
    *why = "eglInitialize failed (" + egl_error() + ")";
    return EGL_NO_CONTEXT;
  }
  const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
  if (!has_extension(extensions, "EGL_KHR_surfaceless_context")) {
    *why = "no EGL_KHR_surfaceless_context";
    return EGL_NO_CONTEXT;
  }
  if (!eglBindAPI(EGL_OPENGL_ES_API)) {
    *why = "no OpenGL ES API (" + egl_error() + ")";
    return EGL_NO_CONTEXT;
  }
  EGLConfig config = nullptr;  // EGL_NO_CONFIG_KHR
  if (!has_extension(extensions, "EGL_KHR_no_config_context")) {
    const EGLint attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT, EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(display, attribs, &config, 1, &count) || count == 0) {
      *why = "no OpenGL ES 3 config";
      return EGL_NO_CONTEXT;
    }
  }
  const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0,
                                    EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
  if (context == EGL_NO_CONTEXT) {
    *why = "no OpenGL ES 3.0 context (" + egl_error() + ")";
    return EGL_NO_CONTEXT;
  }
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    *why = "eglMakeCurrent failed (" + egl_error() + ")";
    eglDestroyContext(display, context);
    return EGL_NO_CONTEXT;
  }
  return context;
}

}  // namespace

EglContext::EglContext() {
  std::lock_guard<std::mutex> lock(g_display_mutex);
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  std::string failures;
  auto attempt = [&](const char* name, EGLDisplay display) {
    std::string why;
    context_ = try_display(display, &why);
    if (context_ != EGL_NO_CONTEXT) {
      display_ = display;
      description_ = std::string("EGL platform ") + name;
      return true;
    }
    if (display != EGL_NO_DISPLAY && g_display_users == 0) eglTerminate(display);
    failures += std::string("\n  ") + name + ": " + why;
    return false;
  };

  bool ok = false;
  if (has_extension(client, "EGL_MESA_platform_surfaceless")) {
    ok = attempt("surfaceless", eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA,
                                                      EGL_DEFAULT_DISPLAY, nullptr));
  } else {
    failures += "\n  surfaceless: EGL_MESA_platform_surfaceless not offered";
  }
  if (!ok && has_extension(client, "EGL_EXT_platform_device")) {
    auto query_devices =
        reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    EGLint count = 0;
    std::vector<EGLDeviceEXT> devices(16);
    if (query_devices && query_devices(16, devices.data(), &count)) {
      for (EGLint i = 0; i < count && !ok; ++i) {
        ok = attempt("device", eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr));
      }
    }
  }
  if (!ok) ok = attempt("default", eglGetDisplay(EGL_DEFAULT_DISPLAY));
  if (!ok) {
    throw std::runtime_error("render: cannot start a headless OpenGL ES 3 context through EGL:" +
                             failures);
  }
  const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  description_ = std::string(version ? version : "?") + ", " + (renderer ? renderer : "?") + ", " +
                 description_;
  int gl_major = 0;
  if (version) std::sscanf(version, "OpenGL ES %d", &gl_major);
  if (gl_major < 3) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    throw std::runtime_error("render: OpenGL ES 3.0 or newer needed, got " + description_);
  }
  ++g_display_users;
}

EglContext::~EglContext() {
  std::lock_guard<std::mutex> lock(g_display_mutex);
  if (eglGetCurrentContext() == context_) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
  eglDestroyContext(display_, context_);
  if (--g_display_users == 0) {
    eglTerminate(display_);
    eglReleaseThread();
  }
}

void EglContext::make_current() {
  if (eglGetCurrentContext() == context_) return;
  if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
    throw std::runtime_error("render: cannot make the OpenGL ES context current on this thread (" +
                             egl_error() + "); a Renderer is used by one thread at a time");
  }
}

}  // namespace convoy::render
