#include "lidar/lidar_scene.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "lidar/reflectivity.h"

namespace convoy::lidar {

namespace {

void check(RTCDevice device, const char* what) {
  const RTCError e = rtcGetDeviceError(device);
  if (e != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("LiDAR scene: Embree failed in ") + what + " (error " +
                             std::to_string(static_cast<int>(e)) + ")");
}

// The inverse transpose of a pose's 3x3 linear part, row-major (column-major input).
std::array<float, 9> normal_matrix(const render::Pose& p) {
  const double a = p[0], b = p[4], c = p[8];   // row 0
  const double d = p[1], e = p[5], f = p[9];   // row 1
  const double g = p[2], h = p[6], i = p[10];  // row 2
  const double det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
  const double s = std::abs(det) > 1e-300 ? 1.0 / det : 0.0;
  // inverse(M)^T = cofactor(M) / det
  return {static_cast<float>((e * i - f * h) * s), static_cast<float>(-(d * i - f * g) * s),
          static_cast<float>((d * h - e * g) * s), static_cast<float>(-(b * i - c * h) * s),
          static_cast<float>((a * i - c * g) * s), static_cast<float>(-(a * h - b * g) * s),
          static_cast<float>((b * f - c * e) * s), static_cast<float>(-(a * f - c * d) * s),
          static_cast<float>((a * e - b * d) * s)};
}

void set_transform(RTCGeometry g, const render::Pose& p) {
  const float m[12] = {float(p[0]),  float(p[1]),  float(p[2]),  float(p[4]),
                       float(p[5]),  float(p[6]),  float(p[8]),  float(p[9]),
                       float(p[10]), float(p[12]), float(p[13]), float(p[14])};
  rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m);
  rtcCommitGeometry(g);
}

}  // namespace

struct LidarScene::Impl {
  RTCDevice device = nullptr;
  RTCScene top = nullptr;
  uint64_t scene_uid = 0;
  std::vector<RTCScene> meshes;  // by render mesh index; null until an instance draws it
  size_t built = 0, triangles = 0;
  struct Tracked {
    RTCGeometry geometry = nullptr;
    render::Pose pose{};
    render::Material material;
    bool visible = true;
  };
  std::vector<Tracked> tracked;             // by render instance index
  std::vector<render::Rgba> texture_means;  // by texture, filled on first use
  std::vector<bool> texture_known;
  bool packets16 = false;

  ~Impl() {
    for (auto& t : tracked)
      if (t.geometry) rtcReleaseGeometry(t.geometry);
    for (RTCScene s : meshes)
      if (s) rtcReleaseScene(s);
    if (top) rtcReleaseScene(top);
    if (device) rtcReleaseDevice(device);
  }

  RTCScene mesh_scene(const render::Scene& scene, int index) {
    if (meshes[index]) return meshes[index];
    const render::MeshData& m = scene.meshes()[index];
    RTCScene s = rtcNewScene(device);
    // Robust: a ray through an edge shared by two triangles hits one of them (no leaks
    // through the ground between triangles).
    rtcSetSceneFlags(s, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.vertex_count()));
    std::memcpy(v, m.positions.data(), m.positions.size() * sizeof(float));
    auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), m.triangle_count()));
    std::memcpy(idx, m.indices.data(), m.indices.size() * sizeof(uint32_t));
    rtcCommitGeometry(g);
    rtcAttachGeometry(s, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(s);
    check(device, "building a mesh");
    ++built;
    triangles += m.triangle_count();
    return meshes[index] = s;
  }

  float reflectivity_of(const render::Scene& scene, const render::Material& m) {
    render::Rgba mean{1, 1, 1, 1};
    if (m.texture >= 0) {
      if (texture_known.size() < scene.textures().size()) {
        texture_known.resize(scene.textures().size(), false);
        texture_means.resize(scene.textures().size());
      }
      if (!texture_known[m.texture]) {
        texture_means[m.texture] = texture_mean(scene.textures()[m.texture]);
        texture_known[m.texture] = true;
      }
      mean = texture_means[m.texture];
    }
    return reflectivity(m, mean);
  }
};

LidarScene::LidarScene(const render::Scene& scene) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.device = rtcNewDevice("threads=2");
  if (!s.device) throw std::runtime_error("LiDAR scene: cannot create an Embree device");
  s.packets16 = rtcGetDeviceProperty(s.device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) != 0;
  s.top = rtcNewScene(s.device);
  rtcSetSceneFlags(s.top, RTC_SCENE_FLAG_DYNAMIC);
  rtcSetSceneBuildQuality(s.top, RTC_BUILD_QUALITY_LOW);
  s.scene_uid = scene.uid();
  update(scene);
}

LidarScene::~LidarScene() = default;

int LidarScene::update(const render::Scene& scene) {
  Impl& s = *impl_;
  if (scene.uid() != s.scene_uid)
    throw std::invalid_argument("LidarScene::update: not the render::Scene it was built from");
  s.meshes.resize(scene.meshes().size(), nullptr);
  const auto& instances = scene.instances();
  int changed = 0;
  for (size_t i = 0; i < instances.size(); ++i) {
    const render::Scene::Instance& in = instances[i];
    if (i == s.tracked.size()) {  // new: its mesh (once) and an Embree instance of it
      Impl::Tracked t;
      t.geometry = rtcNewGeometry(s.device, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(t.geometry, s.mesh_scene(scene, in.mesh));
      rtcSetGeometryTimeStepCount(t.geometry, 1);
      rtcAttachGeometryByID(s.top, t.geometry, static_cast<unsigned>(i));
      t.pose = in.world_from_object;
      set_transform(t.geometry, t.pose);
      t.visible = true;
      t.material = in.material;
      s.tracked.push_back(t);
      InstanceInfo info;
      info.model_id = in.model_id;
      info.class_id = in.class_id;
      info.reflectivity = s.reflectivity_of(scene, in.material);
      info.normal_from_object = normal_matrix(in.world_from_object);
      info_.push_back(info);
      if (!in.visible) {
        rtcDisableGeometry(t.geometry);
        s.tracked.back().visible = false;
      }
      ++changed;
      continue;
    }
    Impl::Tracked& t = s.tracked[i];
    bool any = false;
    if (std::memcmp(t.pose.data(), in.world_from_object.data(), sizeof t.pose) != 0) {
      t.pose = in.world_from_object;
      set_transform(t.geometry, t.pose);
      info_[i].normal_from_object = normal_matrix(t.pose);
      any = true;
    }
    if (t.visible != in.visible) {
      t.visible = in.visible;
      in.visible ? rtcEnableGeometry(t.geometry) : rtcDisableGeometry(t.geometry);
      any = true;
    }
    if (!(t.material == in.material)) {
      t.material = in.material;
      info_[i].reflectivity = s.reflectivity_of(scene, in.material);
    }
    changed += any;
  }
  if (changed) {
    rtcCommitScene(s.top);
    check(s.device, "committing the scene");
  }
  return changed;
}

size_t LidarScene::mesh_count() const { return impl_->built; }
size_t LidarScene::triangle_count() const { return impl_->triangles; }
bool LidarScene::packets16() const { return impl_->packets16; }
void* LidarScene::handle() const { return impl_->top; }

}  // namespace convoy::lidar
