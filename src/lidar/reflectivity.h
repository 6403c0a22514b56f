// A surface's LiDAR reflectivity (near-infrared, 0-1) from its render::Material, which knows
// colours and a texture but not what the surface is. The rule, first match wins (`colour` is
// the diffuse colour times the texture's mean colour, `lum` its luminance
// 0.2126 r + 0.7152 g + 0.0722 b, `spec` the specular colour's mean):
//   glass       alpha < 0.6, or spec >= 0.5 with shininess >= 60 and lum < 0.3 (dark tinted
//               panes), or spec >= 0.6 with blue over red by 0.05 (clear panes)   -> 0.05
//   paint       lum >= 0.8 and spec < 0.4 (lane markings, sign faces, white plates):
//               retro-reflective                                                   -> 0.85
//   vegetation  green over red by 25 % and over blue by 10 %, spec < 0.15          -> 0.45
//   metal/paint spec >= 0.3 (car paint, chrome, galvanised poles)          -> 0.45 + 0.25 lum
//   diffuse     anything else (asphalt 0.09, concrete 0.4)                 -> 0.03 + 0.6 lum^1.5
// The reflectivities are those of lidar intensity datasets in round figures: asphalt dark,
// paint bright, glass nearly nothing back, leaves bright in the near infrared.
#pragma once

#include "render/scene.h"

namespace convoy::lidar {

enum class SurfaceKind { kGlass, kPaint, kVegetation, kMetal, kDiffuse };

// `texture_mean`: the mean RGBA of the material's texture ({1,1,1,1} without one).
SurfaceKind surface_kind(const render::Material& m, const render::Rgba& texture_mean);
float reflectivity(const render::Material& m, const render::Rgba& texture_mean);

// The mean colour of a texture (linear 0-1, from its 8-bit values).
render::Rgba texture_mean(const render::Scene::Texture& t);

}  // namespace convoy::lidar
