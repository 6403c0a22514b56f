#include "lidar/reflectivity.h"

#include <cmath>

namespace convoy::lidar {

namespace {

struct Colour {
  float r, g, b, a, lum, spec;
};

Colour colour_of(const render::Material& m, const render::Rgba& tex) {
  Colour c;
  c.r = m.diffuse[0] * tex[0];
  c.g = m.diffuse[1] * tex[1];
  c.b = m.diffuse[2] * tex[2];
  c.a = m.diffuse[3] * tex[3];
  c.lum = 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
  c.spec = (m.specular[0] + m.specular[1] + m.specular[2]) / 3;
  return c;
}

}  // namespace

SurfaceKind surface_kind(const render::Material& m, const render::Rgba& tex) {
  const Colour c = colour_of(m, tex);
  if (c.a < 0.6f || (c.spec >= 0.5f && m.shininess >= 60 && c.lum < 0.3f) ||
      (c.spec >= 0.6f && c.b > c.r + 0.05f))
    return SurfaceKind::kGlass;
  if (c.lum >= 0.8f && c.spec < 0.4f) return SurfaceKind::kPaint;
  if (c.g > 1.25f * c.r && c.g > 1.1f * c.b && c.spec < 0.15f) return SurfaceKind::kVegetation;
  if (c.spec >= 0.3f) return SurfaceKind::kMetal;
  return SurfaceKind::kDiffuse;
}

float reflectivity(const render::Material& m, const render::Rgba& tex) {
  const Colour c = colour_of(m, tex);
  switch (surface_kind(m, tex)) {
    case SurfaceKind::kGlass:
      return 0.05f;
    case SurfaceKind::kPaint:
      return 0.85f;
    case SurfaceKind::kVegetation:
      return 0.45f;
    case SurfaceKind::kMetal:
      return 0.45f + 0.25f * c.lum;
    case SurfaceKind::kDiffuse:
      break;
  }
  return 0.03f + 0.6f * std::pow(c.lum, 1.5f);
}

render::Rgba texture_mean(const render::Scene::Texture& t) {
  double sum[4] = {0, 0, 0, 0};
  const size_t n = t.rgba.size() / 4;
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < 4; ++k) sum[k] += t.rgba[4 * i + k];
  render::Rgba mean{1, 1, 1, 1};
  if (n == 0) return mean;
  for (int k = 0; k < 4; ++k) mean[k] = static_cast<float>(sum[k] / (255.0 * n));
  return mean;
}

}  // namespace convoy::lidar
