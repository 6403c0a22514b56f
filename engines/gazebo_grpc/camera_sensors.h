// The world's camera sensors: a render::Scene kept in step with the physics, and for each
// SDF <sensor type="camera"> its latest image (with Gazebo's gaussian noise), depth image
// and ground-truth boxes, refreshed at the sensor's update_rate in simulated time.
#pragma once

#include <map>
#include <memory>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "core/two_way.h"
#include "datapack/datapack.h"
#include "physics_world.h"
#include "render/mesh_loader.h"
#include "render/renderer.h"
#include "weather_effects.h"
#include "world_description.h"

namespace convoy::world {

// A vehicle's front and ground in the frame of its first link: how far the front lies ahead
// (+x) and how high the link's origin is above the tyres' contact (camera_sensors.cpp).
struct VehicleExtent {
  double front = 2.0, height = 0.0;
};

// What a world made again (the same description and seed) takes over from the last one's
// cameras: the renderer (its EGL context) and the cameras' noise tables, with the generator
// as it was after drawing them.
struct KeptCameras {
  std::unique_ptr<render::Renderer> renderer;
  std::vector<std::vector<int16_t>> noise;  // by camera
  std::mt19937_64 rng;
  bool has_noise = false;
};

class CameraSensors {
 public:
  // Builds the scene. The renderer (EGL) starts only if the world has a camera. Mesh files
  // come through `files` when given (kept by the caller across worlds made again), else
  // through a cache of its own; `kept`: from release_kept() of the same world's last cameras.
  CameraSensors(const WorldDesc& desc, const PhysicsWorld& physics, uint64_t seed,
                render::MeshFileCache* files = nullptr, KeptCameras kept = {});
  ~CameraSensors();
  // Hands the renderer and the noise tables over (for the next CameraSensors of this world);
  // this one renders no more.
  KeptCameras release_kept();

  size_t count() const { return cameras_.size(); }
  // How many times camera i has rendered: its datapacks change only when this does.
  uint64_t frames(size_t i) const { return cameras_[i].frames; }
  const CameraDesc& camera(size_t i) const { return *cameras_[i].desc; }

  // Renders the cameras that are due at simulated time `t` (seconds).
  void update(double t);
  // A camera renders only once one of its datapacks has been asked for (the first request
  // renders the current view), and depth images and boxes, which cost extra passes, only
  // once they have been asked for: a world whose cameras nobody reads costs no rendering.

  // Actors: models added while running (road users), each one ground-truth instance of class
  // `cls`; link poses in the actor's frame. Returns its index (-1: the world has no camera).
  // With `poses` (an animated walker's), the actor is shown as one of them at a time
  // (set_actor_shown, pose 0 at first) instead of `model`.
  int add_actor(const ModelDesc& model, const std::string& cls,
                const std::vector<ModelDesc>& poses = {});
  void set_actor_pose(int actor, const Eigen::Isometry3d& pose);
  void set_actor_visible(int actor, bool visible);
  void set_actor_shown(int actor, int pose);
  // The model name its ground truth gives (an actor taken over by another road user).
  void set_actor_name(int actor, const std::string& name);

  // The scene instances that draw visual `visual` of link `link` (scoped: model::link) of a
  // world model, in the order added (a mesh file's parts each have one); empty for an
  // unknown visual or a world without cameras. For systems that change a visual's look.
  std::vector<int> visual_instances(const std::string& link, const std::string& visual) const;
  const render::Material& material(int instance) const {
    return scene_.instances()[instance].material;
  }
  void set_material(int instance, const render::Material& m) { scene_.set_material(instance, m); }
  // The scene the cameras render (meshes, posed instances, materials), for other sensors that
  // look at the same world (src/lidar).
  const render::Scene& scene() const { return scene_; }
  render::Scene& scene() { return scene_; }  // (benchmarks hide or move parts of it)
  // Whether the scene was built: the world has a camera or a LiDAR.
  bool has_scene() const { return has_scene_; }
  // The world models' scene instances to their links' current poses (the cameras do it before
  // they render; other sensors call it before they look).
  void refresh_poses();
  // Ground truth of a scene instance's model_id (1-based: the world's models, then actors).
  const std::string& model_name(uint32_t id) const { return model_names_.at(id - 1); }
  const std::string& model_class(uint32_t id) const { return model_classes_.at(id - 1); }
  // What the last frame rendered drew (instances and triangles after culling); null
  // before the first.
  const render::RenderStats* last_render_stats() const {
    return renderer_ && frames_rendered_ > 0 ? &renderer_->last_stats() : nullptr;
  }
  // The weather set last (null until set_weather).
  const Weather* weather() const { return has_weather_ ? &weather_ : nullptr; }

  // The weather from now on (see weather_effects.h): the sun, the sky, fog, wet or snowy
  // ground, rain or snow over the image, and at night the vehicles' headlights and the street
  // lights (the world's point and spot lights named street_light* or lamp*), which are off by
  // day. Until the first call the world's own lights and sky hold.
  void set_weather(const Weather& weather);
  // Sun shadows in every camera (render::Shadows; the engine's Shadows, ShadowDistance).
  void set_shadows(const render::Shadows& shadows) { scene_.set_shadows(shadows); }

  // The latest frame as a convoy.data.Camera datapack.
  void image_datapack(size_t i, datapack::Builder& out);
  // The latest depth image (metres, float32, H x W) as a JSON datapack
  // {"width", "height", "depth": ndarray}.
  void depth_datapack(size_t i, datapack::Builder& out);
  // The latest ground truth as a JSON datapack: {"boxes": [{"model", "class", "instance",
  // "x_min", "y_min", "x_max", "y_max", "pixels", "distance", "visibility"}...]}: every
  // visible model but the ground and the camera's own. distance: metres from the camera to
  // the model's nearest visible part's centre; visibility: the share of its contrast the fog
  // leaves, exp(-3.912 distance / visibility_m) (1 without fog).
  // visible_fraction: the visible box's area over the model's full projected box's (which
  // may reach outside the image): 1 for a model in full view, less where something in front
  // or the image's edge cuts it off (an estimate: a thin pole across it does not count).
  double visibility(double distance) const;
  // The latest instance image as a JSON datapack {"width", "height", "ids": uint32 ndarray
  // H x W (the ground-truth instance id at each pixel, 0 for none: as "instance" in the
  // boxes), "instances": {"<id>": {"model", "class"}}} (the camera's own model and the
  // ground are 0).
  void instances_datapack(size_t i, datapack::Builder& out);
  void boxes_datapack(size_t i, datapack::Builder& out);
  // A segmentation camera's latest label map as a convoy.data.Camera datapack (RGB, 8 bits):
  // semantic: every channel the pixel's class label (class_label()); panoptic: the label, then
  // the instance id's high and low byte (Gazebo's layout; the ids of "instances" above). With
  // `colored`: the same as colours to look at (a colour per class; per instance if panoptic).
  void segmentation_datapack(size_t i, bool colored, datapack::Builder& out);

 private:
  struct Camera {
    const CameraDesc* desc = nullptr;
    int link = -1;           // physics link index
    uint32_t own_model = 0;  // the model carrying the camera: not in its ground truth
    double next_update = 0;
    bool rendered = false;
    uint64_t frames = 0;
    render::Frame frame;
    int depth_channels = 3;
    std::vector<int16_t> noise;         // mean + stddev * N(0,1) in 0..255 units, a fixed table
    const int16_t* noise_at = nullptr;  // the current frame's samples (null: no noise)
    bool want_ids = false;              // instances asked for once
    bool want_image = false, want_depth = false, want_boxes = false;  // asked for once:
                                                                      // rendered from then on
    bool has_depth = false, has_boxes = false, has_ids = false;       // the current frame has them
  };
  struct Tracked {
    int link;                    // physics link index
    std::vector<int> instances;  // scene instances of this link's visuals
    std::vector<render::Pose> offsets;
  };
  // A vehicle that lights the road at night: a world model (its first link tracked) or an
  // actor of class car, bus or truck; extent: its front and the ground in that frame.
  struct Vehicle {
    uint32_t model_id;
    int link = -1;   // physics link (world models)
    int actor = -1;  // actor index (actors)
    VehicleExtent extent;
  };
  struct Actor {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    bool visible = false;
    std::vector<int> instances;
    std::vector<render::Pose> offsets;          // each instance in its link's frame
    std::vector<Eigen::Isometry3d> link_poses;  // its link in the actor's frame
    std::vector<int> pose_of;                   // each instance's pose (-1: not animated)
    int shown = 0;                              // the pose shown
    uint32_t label = 0;                         // its model_id in the ground truth
  };
  bool shows(const Actor& a, size_t instance) const {
    return a.visible && (a.pose_of[instance] < 0 || a.pose_of[instance] == a.shown);
  }
  void pose_instance(const Actor& a, size_t k);  // instance k to the actor's pose
  void show_actor(const Actor& a);  // its instances shown or hidden (those shown posed)
  // A mesh file's parts, loaded, simplified into levels of detail and added to the scene once
  // for every visual and actor that uses the file at that scale.
  struct FilePart {
    int mesh;                        // the Scene's mesh (with its coarser levels)
    render::Material file_material;  // the file's material for it, with its texture
  };
  const std::vector<FilePart>& file_mesh(const std::string& path, const Eigen::Vector3d& scale);
  void build_scene(const WorldDesc& desc);
  void draw_noise_tables();
  // The scene's lights, sky and atmosphere for camera `cam` under weather_.
  void apply_weather(const Camera& cam, const Eigen::Isometry3d& camera_pose);
  // Adds the scene instances of a link's visuals, the link placed at `placement`, labelled
  // `label` (0: no ground truth), into `tracked`; a world model's (`world`) also into
  // visual_instances_.
  void add_visuals(const LinkDesc& link, const Eigen::Isometry3d& placement, uint32_t label,
                   Tracked* tracked, bool world = false);
  void render(Camera& cam);
  void first_render(Camera& cam);  // on the first request: render now, schedule the next
  void ensure_ids(Camera& cam);    // the current frame with its instance ids (asked for once)
  void draw_noise(Camera& cam);
  // The frame's pixels (RGB or grey, with its noise) into `dst`.
  void convert(const Camera& cam, std::span<uint8_t> dst) const;

  const PhysicsWorld& physics_;
  std::unique_ptr<render::Renderer> renderer_;
  render::Scene scene_;
  std::vector<Camera> cameras_;
  std::vector<Tracked> tracked_;
  std::vector<Actor> actors_;
  std::map<std::string, std::vector<FilePart>> file_meshes_;  // by path and scale
  render::MeshFileCache own_files_;
  render::MeshFileCache* files_ = &own_files_;
  std::map<std::pair<std::string, std::string>, std::vector<int>>
      visual_instances_;                                  // (link, visual) -> scene instances
  std::vector<std::string> model_names_, model_classes_;  // by model_id - 1
  std::mt19937_64 rng_;
  std::mt19937_64 rng_after_tables_;  // rng_ once the noise tables were drawn
  mutable TwoWay split_;              // the frame conversion's second thread
  double now_ = 0;
  std::vector<render::Light> base_lights_;
  std::vector<bool> street_light_;  // by base light
  std::vector<uint32_t> ids_;       // instances_datapack's, reused
  render::Rgba base_ambient_{}, base_background_{};
  std::vector<Vehicle> vehicles_;
  bool has_weather_ = false;
  bool has_scene_ = false;
  uint64_t frames_rendered_ = 0;  // by every camera
  Weather weather_;               // simulated time of the last update()
};

}  // namespace convoy::world
