#!/usr/bin/python3
"""convoy_gym benchmark: DrivingEnv.step() calls per second, 1 process, no camera, then
with an 84 x 84 camera, then VectorDrivingEnv(N)'s total steps per second (N servers stepped
together).

  /usr/bin/python3 benchmarks/gym_bench.py [--steps 3000] [--runs 3] [--physics-step 0.005]
                                           [--envs N] [--camera 84x84]

One DrivingEnv on experiments/rl_parkring (Gazebo's smart car, the weather engine, the
python_json agent engine, drive_tf and the observe status function; 0.05 s per step). Each
run resets with a new seed and times --steps step() calls of a heading-error policy at
6 m/s, resetting when an episode ends (resets are timed too). A second figure times the
same number of bare nrp_client run_loop(1) calls on the same server, to show what the
environment adds. Then the same with DrivingEnv(physics_step=...) (default 0.005 s instead
of the world's 1 ms physics step; 0 skips it). Prints each run, the medians and the CPU model.
The issue's target is 2,000 steps/s (MetaDrive: "1000+ FPS").

--envs N (default: 1 then 2): after the single environment, VectorDrivingEnv(N) runs the same
policy in each of its N environments for --steps vector steps per run (N x --steps
environment steps, autoresets included), and the total environment steps per second is
compared with the single environment's (the ratio; the issue's target for 2 environments on
2 cores is 1.6). --envs 1 times the single environment only.

--camera HxW (default 84x84; "none" skips it): DrivingEnv(camera=(H, W)) at the world's
physics step, the same policy and runs (each step also brings the ego camera's H x W frame,
rendered by the world engine). Printed as `env steps/s with camera: N` beside
`env steps/s without camera: N` (the issue's target with an 84 x 84 camera: 300).
"""
import argparse
import os
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from machine import cpu_model  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "python"))
import numpy as np  # noqa: E402

from convoy_gym import DrivingEnv, VectorDrivingEnv  # noqa: E402


def other_simulations():
    """NRPCoreSim processes that are not this benchmark's (they take cores from it)."""
    def pgrep(*args):
        return subprocess.run(["pgrep"] + list(args), capture_output=True,
                              text=True).stdout.split()
    try:
        return len(set(pgrep("-f", "NRPCoreSim")) - set(pgrep("-P", str(os.getpid()))))
    except OSError:
        return 0


def note():
    n = other_simulations()
    return "  [%d other NRPCoreSim running: figures are contended]" % n if n else ""


def state(obs):
    """The state vector of an observation (with a camera, obs["state"])."""
    return obs["state"] if isinstance(obs, dict) else obs


def time_env(env, steps, seed):
    obs, _ = env.reset(seed=seed)
    t0 = time.perf_counter()
    for _ in range(steps):
        action = np.array([np.clip(0.8 * state(obs)[4], -0.55, 0.55), 6.0], dtype=np.float32)
        obs, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            obs, _ = env.reset()
    return steps / (time.perf_counter() - t0)


def time_vector(envs, steps, seed):
    """Total environment steps per second of `steps` vector steps (autoresets included)."""
    obs, _ = envs.reset(seed=seed)
    speed = np.full(envs.num_envs, 6.0)
    t0 = time.perf_counter()
    for _ in range(steps):
        actions = np.stack([np.clip(0.8 * obs[:, 4], -0.55, 0.55), speed], axis=1)
        obs, _, _, _, _ = envs.step(actions)
    return steps * envs.num_envs / (time.perf_counter() - t0)


def time_client(env, steps):
    nrp = env._nrp  # the bare client under the environment, the same policy
    obs, _ = env.reset(seed=0)
    heading_error = float(obs[4])
    t0 = time.perf_counter()
    for _ in range(steps):
        steer = max(-0.55, min(0.55, 0.8 * heading_error))
        nrp.set_json_datapack("action", "agent", {"steer": steer, "speed": 6.0})
        _, data = nrp.run_loop(1)
        heading_error = data[-1]["heading_error"]
    return steps / (time.perf_counter() - t0)


def time_camera(size, steps, runs):
    """The median steps/s of DrivingEnv(camera=size) over `runs` runs, each printed."""
    with DrivingEnv(max_steps=100000, camera=size) as env:
        time_env(env, 100, seed=99)  # warm-up
        rates = []
        for run in range(runs):
            rates.append(time_env(env, steps, seed=run))
            print("camera %dx%d, run %d: %.0f steps/s%s"
                  % (size[0], size[1], run + 1, rates[-1], note()), flush=True)
    return statistics.median(rates)


def camera_size(text):
    if text.lower() == "none":
        return None
    try:
        height, width = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError("--camera: HxW (84x84) or none, got %r" % text)
    return height, width


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=3000, help="timed steps per run")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--physics-step", type=float, default=0.005,
                        help="also time DrivingEnv(physics_step=S) (0: skip)")
    parser.add_argument("--envs", type=int, default=2,
                        help="also time VectorDrivingEnv(N) against one env (1: skip)")
    parser.add_argument("--camera", type=camera_size, default=(84, 84),
                        help="also time DrivingEnv(camera=(H, W)), HxW (none: skip)")
    args = parser.parse_args()
    medians, vector, camera = {}, {}, None
    for physics_step in (None, args.physics_step or None):
        if physics_step is None and medians:
            break
        name = "world's step" if physics_step is None else "physics_step %g s" % physics_step
        # max_steps beyond a timed run, so that episodes end only on the track's account
        with DrivingEnv(max_steps=100000, physics_step=physics_step) as env:
            time_env(env, 100, seed=99)  # warm-up
            rates = []
            for run in range(args.runs):
                rates.append(time_env(env, args.steps, seed=run))
                print("%s, run %d: %.0f steps/s%s" % (name, run + 1, rates[-1], note()),
                      flush=True)
            bare = time_client(env, args.steps)
        print("%s, bare run_loop(1) on the same server: %.0f calls/s" % (name, bare))
        medians[physics_step] = statistics.median(rates)
        if physics_step is None and args.camera:
            camera = time_camera(args.camera, args.steps, args.runs)
        if args.envs > 1:
            with VectorDrivingEnv(args.envs, max_steps=100000,
                                  physics_step=physics_step) as envs:
                time_vector(envs, 100, seed=99)  # warm-up
                rates = []
                for run in range(args.runs):
                    rates.append(time_vector(envs, args.steps, seed=10 * run))
                    print("%s, VectorDrivingEnv(%d), run %d: %.0f total steps/s%s"
                          % (name, args.envs, run + 1, rates[-1], note()), flush=True)
            vector[physics_step] = statistics.median(rates)
    print("CPU: %s (%d cores)" % (cpu_model(), os.cpu_count()))
    print("DrivingEnv steps/s: %.0f" % medians[None])
    print("env steps/s without camera: %.0f" % medians[None])
    if args.camera:
        print("env steps/s with camera: %.0f (%dx%d)" % ((camera,) + tuple(args.camera)))
    if None in vector:
        print("VectorDrivingEnv(%d) total steps/s: %.0f (ratio %.2f)"
              % (args.envs, vector[None], vector[None] / medians[None]))
    for physics_step, rate in medians.items():
        if physics_step is not None:
            print("DrivingEnv steps/s with physics_step %g s: %.0f" % (physics_step, rate))
            if physics_step in vector:
                print("VectorDrivingEnv(%d) total steps/s with physics_step %g s: %.0f "
                      "(ratio %.2f)" % (args.envs, physics_step, vector[physics_step],
                                        vector[physics_step] / rate))


if __name__ == "__main__":
    main()
