#include "render/frustum.h"

#include <cmath>

#include "render/renderer.h"

namespace convoy::render {

ViewFrustum::ViewFrustum(const CameraSpec& spec) : ViewFrustum(spec, spec.far_clip) {}

ViewFrustum::ViewFrustum(const CameraSpec& spec, double far_clip)
    : tx_(std::tan(spec.hfov / 2)),
      ty_(tx_ * spec.height / spec.width),
      nx_(std::sqrt(1 + tx_ * tx_)),
      ny_(std::sqrt(1 + ty_ * ty_)),
      near_(spec.near_clip),
      far_(far_clip) {}

void ViewFrustum::outside(const glm::dvec3& p, double d[6]) const {
  d[0] = p.z + near_;  // in front of the near plane (eye space looks down -z)
  d[1] = -p.z - far_;  // beyond the far plane
  d[2] = (p.x + p.z * tx_) / nx_;
  d[3] = (-p.x + p.z * tx_) / nx_;
  d[4] = (p.y + p.z * ty_) / ny_;
  d[5] = (-p.y + p.z * ty_) / ny_;
}

bool ViewFrustum::misses_sphere(const glm::dvec3& c, double r) const {
  double d[6];
  outside(c, d);
  for (double v : d) {
    if (v > r) return true;
  }
  return false;
}

bool ViewFrustum::misses_capsule(const glm::dvec3& a, const glm::dvec3& b, double r) const {
  double da[6], db[6];
  outside(a, da);
  outside(b, db);
  for (int i = 0; i < 6; ++i) {
    if (da[i] > r && db[i] > r) return true;
  }
  return false;
}

}  // namespace convoy::render
