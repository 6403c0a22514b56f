// One Renderer for all of a test binary's tests (EGL starts once); a test fails with EGL's
// message where no context can be had, rather than skip.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "render/renderer.h"

namespace convoy::render {

inline Renderer* shared_renderer() {
  static std::unique_ptr<Renderer> renderer;
  static std::string error;
  if (!renderer && error.empty()) {
    try {
      renderer = std::make_unique<Renderer>();
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  if (!renderer) ADD_FAILURE() << "cannot start the renderer: " << error;
  return renderer.get();
}

}  // namespace convoy::render
