// Physics real-time factor of a four-wheeled car with two steering joints at a 1 ms step,
// driven by the report's joint PID values (rear wheels: velocity P 10; steering: position
// P 40000 I 200 D 1). Prints the median of 5 runs of 20 simulated seconds.
//   build/benchmarks/world_bench [world.sdf]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "joint_pid.h"
#include "physics_world.h"
#include "world_description.h"

using namespace convoy::world;

int main(int argc, char** argv) {
  std::string file = argc > 1 ? argv[1] : CONVOY_BENCH_DIR "/world/car_world.sdf";
  WorldDesc desc = load_world(file);
  std::vector<double> rtfs;
  double final_x = 0;
  for (int run = 0; run < 5; ++run) {
    PhysicsWorld p(desc);
    struct C {
      int joint;
      bool velocity;
      JointPid pid;
    };
    std::vector<C> cs;
    for (const auto& m : desc.models)
      for (const auto& [plugin, pids] : m.joint_plugins)
        for (const auto& pd : pids)
          cs.push_back({p.joint_index(pd.joint), pd.velocity,
                        JointPid(pd.p, pd.i, pd.d, pd.i_max, pd.i_min)});
    const double sim_seconds = 20, dt = p.step_size();
    auto t0 = std::chrono::steady_clock::now();
    for (long i = 0; i < std::lround(sim_seconds / dt); ++i) {
      double t = i * dt;
      double omega = 10.0, steer = 0.2 * std::sin(0.5 * t);  // drive and weave
      for (auto& c : cs) {
        auto s = p.joint_state(c.joint);
        double target = c.velocity ? omega : steer;
        p.set_joint_effort(c.joint,
                           c.pid.update((c.velocity ? s.velocity : s.position) - target, dt));
      }
      p.step();
    }
    double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    rtfs.push_back(sim_seconds / wall);
    for (const auto& m : desc.models)
      if (!m.joint_plugins.empty())
        final_x = p.link_state(p.link_index(m.name + "::base_link")).position.x();
  }
  std::sort(rtfs.begin(), rtfs.end());
  std::printf(
      "car (4 wheels, 2 steering joints), 1 ms step: real-time factor median %.1fx "
      "(runs: %.1f %.1f %.1f %.1f %.1f)  target >= 20x   [car travelled %.1f m]\n",
      rtfs[2], rtfs[0], rtfs[1], rtfs[2], rtfs[3], rtfs[4], final_x);
}
