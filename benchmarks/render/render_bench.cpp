// Camera rendering benchmark: frames per second of a 736x480 camera over a scene of about
// 100k triangles (spheres, cylinders and boxes on a ground plane, several materials, two
// lights), for colour only, colour + depth, and colour + depth + bounding boxes, with the
// renderer's levels of detail (Renderer::kLodPixelError); colour only at full detail; and all
// three in rain with fog on a wet ground, in snow on a snowy ground (render/scene.h's
// Atmosphere), and with sun shadows (Scene::set_shadows).
// Each frame moves every object, renders and reads the images back.
//
//   render_bench [frames_per_run=300] [runs=5] [first_frame.ppm]
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "render/image_io.h"
#include "render/renderer.h"

using namespace convoy::render;

namespace {

// CPU time of the whole process (all llvmpipe threads), seconds.
double cpu_seconds() {
  rusage u;
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

struct Body {
  int instance;
  double x, y, z, phase;
};

std::vector<Body> build_scene(Scene* scene) {
  scene->set_background({0.6f, 0.75f, 0.95f, 1});
  Light sun;
  sun.direction = {-0.3f, 0.4f, -0.85f};
  scene->add_light(sun);
  Light lamp;
  lamp.type = Light::kPoint;
  lamp.position = {12, -3, 4};
  lamp.diffuse = {0.9f, 0.7f, 0.4f, 1};
  lamp.attenuation_linear = 0.1f;
  lamp.range = 40;
  scene->add_light(lamp);

  // Levels of detail as the world engine makes them for SDF spheres and cylinders.
  const int sphere = scene->add_mesh_levels(sphere_levels(0.4f, 24, 48));  // 2208 triangles
  const int cylinder = scene->add_mesh_levels(cylinder_levels(0.3f, 1.0f, 32));
  const int box = scene->add_mesh(make_box(0.7f, 0.7f, 0.7f));
  const int ground = scene->add_mesh(make_plane(200, 200));
  Material grass;
  grass.diffuse = grass.ambient = {0.35f, 0.5f, 0.3f, 1};
  scene->add_instance(ground, grass, make_pose(0, 0, 0));

  std::vector<Material> paints(6);
  const float colours[6][3] = {{0.8f, 0.1f, 0.1f}, {0.1f, 0.6f, 0.2f}, {0.2f, 0.3f, 0.9f},
                               {0.9f, 0.8f, 0.1f}, {0.7f, 0.7f, 0.7f}, {0.5f, 0.2f, 0.6f}};
  for (int i = 0; i < 6; ++i) {
    paints[i].diffuse = paints[i].ambient = {colours[i][0], colours[i][1], colours[i][2], 1};
    paints[i].specular = {0.4f, 0.4f, 0.4f, 1};
  }
  // Rows of objects in front of the camera, spread across its field of view; four in seven
  // are spheres.
  std::vector<Body> bodies;
  uint32_t id = 1;
  const int rows = 12, columns = 7;
  for (int row = 0; row < rows; ++row) {
    const double x = 6 + 2.5 * row;
    for (int c = 0; c < columns; ++c) {
      const double y = (c - (columns - 1) / 2.0) / ((columns - 1) / 2.0) * 0.42 * x;
      const int kind = (4 * row + c) % 7;
      const int mesh = kind < 4 ? sphere : kind < 6 ? cylinder : box;
      const double z = mesh == cylinder ? 0.5 : 0.4;
      const int instance =
          scene->add_instance(mesh, paints[(row + c) % 6], make_pose(x, y, z), id++, 1 + kind % 3);
      bodies.push_back(Body{instance, x, y, z, 0.1 * (row * columns + c)});
    }
  }
  return bodies;
}

}  // namespace

int main(int argc, char** argv) {
  const int frames = argc > 1 ? std::atoi(argv[1]) : 300;
  const int runs = argc > 2 ? std::atoi(argv[2]) : 5;
  Renderer renderer;
  Scene scene;
  std::vector<Body> bodies = build_scene(&scene);
  size_t triangles = 0;
  for (const auto& inst : scene.instances()) {
    triangles += scene.meshes()[inst.mesh].triangle_count();
  }
  const CameraSpec spec{736, 480, 1.047, 0.1, 100};
  const Pose camera = make_pose(0, 0, 1.6, 0, 0.12, 0);
  Frame frame;
  renderer.render(scene, camera, spec, &frame, true, true);
  if (argc > 3) write_ppm(argv[3], frame.width, frame.height, frame.rgb.data());
  std::printf("render_bench: %s\n", renderer.description().c_str());
  const RenderStats& stats = renderer.last_stats();
  std::printf("scene: %zu instances, %zu triangles (full detail); in view: %d instances; %dx%d\n",
              scene.instances().size(), triangles, stats.instances_drawn, spec.width, spec.height);
  std::printf("median of %d runs of %d frames (each: move all objects, render, read back)\n", runs,
              frames);

  struct Mode {
    const char* name;
    bool depth, boxes;
    double lod_pixel_error;
    int weather;  // 0 clear, 1 rain 0.7 + fog 100 m + wet ground, 2 snow 0.5 + snowy ground
    bool shadows = false;
  };
  const Mode modes[] = {{"rgb", false, false, Renderer::kLodPixelError, 0},
                        {"rgb+depth", true, false, Renderer::kLodPixelError, 0},
                        {"rgb+depth+boxes", true, true, Renderer::kLodPixelError, 0},
                        {"rgb, full detail", false, false, 0.0, 0},
                        {"all, rain+fog", true, true, Renderer::kLodPixelError, 1},
                        {"all, snow", true, true, Renderer::kLodPixelError, 2},
                        {"all, shadows", true, true, Renderer::kLodPixelError, 0, true}};
  long step = 0;
  for (const Mode& mode : modes) {
    std::vector<double> fps, cpu_ms;
    renderer.set_lod_pixel_error(mode.lod_pixel_error);
    Shadows shadows;
    shadows.enabled = mode.shadows;
    scene.set_shadows(shadows);
    Atmosphere atmosphere;
    if (mode.weather == 1) {
      atmosphere.visibility = 100;
      atmosphere.wetness = 1;
      atmosphere.precipitation = 0.7f;
      atmosphere.fall_slant = 0.1f;
    } else if (mode.weather == 2) {
      atmosphere.snow_cover = 1;
      atmosphere.precipitation = 0.5f;
      atmosphere.snow = true;
    }
    for (int run = -1; run < runs; ++run) {  // run -1 warms up
      const int n = run < 0 ? 30 : frames;
      const double cpu_start = cpu_seconds();
      const auto start = std::chrono::steady_clock::now();
      for (int i = 0; i < n; ++i, ++step) {
        for (const Body& b : bodies) {
          const double t = 0.01 * step + b.phase;
          scene.set_pose(b.instance, make_pose(b.x, b.y, b.z + 0.1 * std::sin(t), 0, 0, t));
        }
        atmosphere.time = 0.02 * static_cast<double>(step);
        scene.set_atmosphere(atmosphere);
        renderer.render(scene, camera, spec, &frame, mode.depth, mode.boxes);
      }
      const double s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (run >= 0) {
        fps.push_back(n / s);
        cpu_ms.push_back(1e3 * (cpu_seconds() - cpu_start) / n);
      }
    }
    std::sort(fps.begin(), fps.end());
    std::sort(cpu_ms.begin(), cpu_ms.end());
    std::printf(
        "  %-16s %7.1f frames/s  (runs: %.1f .. %.1f)  CPU %.1f ms/frame  triangles drawn %zu "
        "(%d instances at a coarser level)  boxes: %zu\n",
        mode.name, fps[fps.size() / 2], fps.front(), fps.back(), cpu_ms[cpu_ms.size() / 2],
        renderer.last_stats().triangles_drawn, renderer.last_stats().coarser_level,
        frame.boxes.size());
  }
  return 0;
}
