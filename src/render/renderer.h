// Headless rendering of camera sensors: colour, depth and ground-truth bounding boxes.
//
// The world engine keeps a Scene in step with its bodies and asks a Renderer for each camera's
// frame. Rendering is OpenGL ES 3 through EGL without a display (Mesa's llvmpipe on a plain
// CPU machine): Blinn-Phong lighting per pixel (per vertex on meshes whose triangles cover
// under kPerVertexLightingBelow pixels), textures multiplying the diffuse and ambient colours.
// Weather (Scene::set_atmosphere): fog, wet and snowy surfaces, rain and snow over the image.
// Sun shadows through a shadow map (Scene::set_shadows), a sky gradient (Scene::set_sky).
// Not drawn: transparency (alpha is ignored), anti-aliasing, sky boxes. The output is
// deterministic: the same scene, pose and spec give the same bytes on the same machine.
//
// Cost (llvmpipe, 2 cores, 736x480): about 1 ms per frame for clearing and reading back, and
// roughly 150 ns of CPU per triangle in view (tiny triangles cost as much as big ones), so a
// 100k-triangle view renders at 80-90 frames/s at full detail, and above 150 with the levels
// of detail (set_lod_pixel_error); see benchmarks/render/render_bench.cpp.
// Depth adds a float attachment and its readback, boxes an id attachment and a pass over it.
//
// Camera convention (Gazebo / SDF): the camera looks along its +X axis, +Z is up in the
// image, +Y is to the image's left. The image is an ideal pinhole with square pixels:
// fx = fy = (width / 2) / tan(hfov / 2), principal point (width / 2, height / 2), pixel (u, v)
// covering [u, u+1) x [v, v+1) with v = 0 the top row.
//
//   Renderer renderer;                     // throws if no OpenGL ES 3 context can be had
//   CameraSpec spec{736, 480, 1.047, 0.1, 100};
//   Frame frame;                           // reuse it: its buffers are kept
//   renderer.render(scene, camera_pose, spec, &frame, /*want_depth=*/true, /*want_boxes=*/true);
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "render/pose.h"
#include "render/scene.h"

namespace convoy::render {

// SDF <camera>: image size, horizontal field of view and clip distances (defaults are SDF's).
struct CameraSpec {
  int width = 320;
  int height = 240;
  double hfov = 1.047;  // radians, in (0, pi)
  double near_clip = 0.1;
  double far_clip = 100.0;
};

// A labelled model's extent in the image: the pixels where it is visible (not occluded, not
// outside the image). Instances sharing a model_id make one box.
struct BoundingBox {
  uint32_t model_id;
  uint32_t class_id;               // that of the model's first instance (lowest index)
  int x_min, y_min, x_max, y_max;  // inclusive pixel coordinates, y = 0 the top row
  uint32_t pixel_count;            // visible pixels
  // Metres from the camera to the nearest bounding-sphere centre of its visible instances.
  float distance = std::numeric_limits<float>::infinity();
  // Where the whole model would be in the image were nothing in front of it and the image
  // unbounded: its instances' bounding boxes projected (pixels, may lie outside the image;
  // +-1e6 where a part is behind the camera). With the visible box, a measure of occlusion
  // and truncation.
  float full_x_min = 0, full_y_min = 0, full_x_max = 0, full_y_max = 0;
};

struct Frame {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // height x width x 3, row 0 = top of the image
  // Set by the caller: leave the colour as read back, in `rgba` (height x width x 4, alpha
  // 255), and `rgb` empty. A caller that converts the pixels anyway (the world engine's
  // cameras, straight into the outgoing shared memory) saves a copy of the frame.
  bool keep_rgba = false;
  std::vector<uint8_t> rgba;
  // Set by the caller: with boxes, also keep `model_ids`: height x width, the model_id of the
  // labelled model seen at each pixel (0: none, or an unlabelled one), row 0 = top.
  bool keep_ids = false;
  std::vector<uint32_t> model_ids;
  // height x width distances in metres along the optical axis (camera +X), row 0 = top;
  // +infinity where nothing lies within the clip range. Empty unless asked for.
  std::vector<float> depth;
  // One per labelled model (model_id != 0) with a visible pixel, by increasing model_id.
  // Empty unless asked for.
  std::vector<BoundingBox> boxes;
};

// What the last render drew, after culling instances outside the view.
struct RenderStats {
  int instances_drawn = 0;
  size_t triangles_drawn = 0;
  int per_vertex_lit = 0;  // instances lit per vertex (see set_per_vertex_lighting_below)
  int coarser_level = 0;   // instances drawn with a coarser level of detail
};

class Renderer {
 public:
  using Frame = render::Frame;
  using BoundingBox = render::BoundingBox;

  // Starts the OpenGL ES context. Throws std::runtime_error saying why if EGL or OpenGL ES 3
  // cannot start. One Renderer per process is the intended use; it is not thread-safe, and
  // must be used (and destroyed) by one thread at a time. It also calls
  // tune_allocator_for_frames() (core/memory.h): llvmpipe allocates its bins afresh every
  // frame, and memory handed back to the system would fault in again each time.
  Renderer();
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Renders `scene` seen from `camera_world_pose` (world-from-camera, rigid) into `out`,
  // reusing its buffers. The first render of a Scene uploads its meshes and textures; later
  // renders upload only what was added since. Throws std::invalid_argument for a bad spec and
  // std::runtime_error on a GPU error.
  void render(const Scene& scene, const Pose& camera_world_pose, const CameraSpec& spec, Frame* out,
              bool want_depth = false, bool want_boxes = false);

  // Lighting is per pixel, except for an instance whose triangles cover on average fewer than
  // this many pixels (estimated from its bounding sphere): there it is computed per vertex,
  // which looks the same at that size and costs far less on a software rasteriser. 0 lights
  // everything per pixel.
  static constexpr double kPerVertexLightingBelow = 4.0;
  void set_per_vertex_lighting_below(double pixels_per_triangle);

  // Levels of detail (Scene::add_mesh_levels): an instance is drawn with the coarsest level
  // of its mesh whose geometric error, at the instance's nearest point, covers at most this
  // many pixels. 0 draws every mesh at full detail.
  static constexpr double kLodPixelError = 1.0;
  void set_lod_pixel_error(double pixels);

  const RenderStats& last_stats() const;
  // OpenGL ES version, renderer and EGL platform, for logs.
  const std::string& description() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace convoy::render
