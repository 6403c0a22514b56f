// The camera's view frustum in eye space, for culling: what the camera cannot see, and what
// cannot cast a shadow onto anything it sees.
//
// Eye space is OpenGL's: the camera at the origin looking down -z, +y up. The four side
// planes pass through the eye; near and far are the clip distances.
//
//   ViewFrustum f(spec);
//   if (f.misses_sphere(centre_in_eye, radius)) continue;                 // not in view
//   if (f.misses_capsule(centre_in_eye, shadow_end_in_eye, radius)) ...   // shadow not in view
#pragma once

#include <glm/glm.hpp>

namespace convoy::render {

struct CameraSpec;

class ViewFrustum {
 public:
  explicit ViewFrustum(const CameraSpec& spec);
  // The same frustum with its far plane at `far_clip` metres instead.
  ViewFrustum(const CameraSpec& spec, double far_clip);

  // True when no point within `r` of `c` lies inside the frustum by any one plane's test (a
  // sphere that the test keeps may still miss it near an edge: conservative).
  bool misses_sphere(const glm::dvec3& c, double r) const;
  // The same for the segment a-b swept by a sphere of radius `r`: a caster and the shadow it
  // throws.
  bool misses_capsule(const glm::dvec3& a, const glm::dvec3& b, double r) const;

  // tan of the half angles (horizontal, vertical).
  double tan_x() const { return tx_; }
  double tan_y() const { return ty_; }

 private:
  // Signed distances outside each of the six planes (positive: outside).
  void outside(const glm::dvec3& p, double d[6]) const;
  double tx_, ty_, nx_, ny_, near_, far_;
};

}  // namespace convoy::render
